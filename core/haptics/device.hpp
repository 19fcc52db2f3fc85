#pragma once
/// The device interface every backend implements (replay, scripted, keyboard, network console).
///
/// Threading: poll() and send() are called from the servo thread only, once per tick; they must
/// not block, allocate or take a lock. Everything else is called before the servo thread starts
/// or after it stopped.
#include "haptics/types.hpp"

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

namespace viscera::haptics {

/// Counters a backend keeps about its link (the network console fills most of them).
struct LinkStats {
    uint64_t received = 0;          ///< samples/packets accepted
    uint64_t rejectedMalformed = 0; ///< wrong size, bad magic, bad field, non-finite value
    uint64_t rejectedVersion = 0;   ///< protocol version this build does not speak
    uint64_t rejectedAuth = 0;      ///< MAC mismatch (forged, corrupted or of another session), or no session yet
    uint64_t rejectedOrder = 0;     ///< duplicate or out-of-order sequence numbers (a replay)
    uint64_t rejectedJump = 0;      ///< sequence too far ahead of the last accepted one
    uint64_t rejectedPeer = 0;      ///< from another address than the console's
    uint64_t staleWelcomes = 0;     ///< welcomes that answer no pending hello (late or replayed)
    uint64_t handshakes = 0;        ///< sessions opened (hello answered by a valid welcome)
    uint64_t droppedFlood = 0;      ///< valid packets superseded within one tick (only the newest is used)
    uint64_t sent = 0;              ///< commands sent
    uint64_t sendErrors = 0;
    uint64_t disconnects = 0; ///< connected → disconnected transitions
    uint64_t reconnects = 0;  ///< disconnected → connected transitions (after a first connection)
};

class Device {
public:
    virtual ~Device() = default;
    virtual const DeviceCapabilities& capabilities() const = 0;
    /// Fills `out` with the newest state at time now_ns (servo clock). out.connected is false
    /// when the device has not answered within its timeout; the rest of `out` then holds the
    /// last good sample. Never blocks.
    virtual void poll(int64_t now_ns, DeviceState& out) = 0;
    /// Renders a command (already through the safety filter). Never blocks.
    virtual void send(const DeviceCommand& command) = 0;
    virtual LinkStats linkStats() const { return {}; }
    /// Short backend name for reports: "replay", "scripted", "keyboard", "console".
    virtual const char* backend() const = 0;
};

/// A device inside this process (replay, scripted, keyboard): keeps the last command and counts
/// polls and commands for linkStats(). Subclasses call countPoll() at the end of poll().
class LocalDevice : public Device {
public:
    void send(const DeviceCommand& command) override {
        m_lastCommand = command;
        m_sent.fetch_add(1, std::memory_order_relaxed);
    }
    LinkStats linkStats() const override {
        LinkStats s;
        s.received = m_polls.load(std::memory_order_relaxed);
        s.sent = m_sent.load(std::memory_order_relaxed);
        return s;
    }
    /// The last command sent (read after the servo thread stopped).
    const DeviceCommand& lastCommand() const { return m_lastCommand; }

protected:
    void countPoll() { m_polls.fetch_add(1, std::memory_order_relaxed); }

private:
    DeviceCommand m_lastCommand;
    std::atomic<uint64_t> m_polls{0}, m_sent{0};
};

} // namespace viscera::haptics
