#pragma once
/// Network backend for the bimanual console (2 × 7-DOF masters with grip, 5 pedals, [B §4]) over
/// UDP, protocol version 1 (console_protocol.hpp, packaging/console-protocol.md).
///
/// The player binds an ephemeral local port and sends a command packet every servo tick to the
/// console's address; the console answers with state packets to the address the commands come
/// from. poll() drains at most maxPacketsPerPoll datagrams per tick and keeps the newest valid
/// one; malformed, wrong-version, corrupted and out-of-order packets are counted and ignored.
/// With no valid packet for `timeout`, the device reports disconnected (the safety filter then
/// zeroes the force); the next valid packet reconnects it.
#include "haptics/console_protocol.hpp"
#include "haptics/device.hpp"
#include "haptics/udp_socket.hpp"

#include <atomic>
#include <memory>

namespace viscera::haptics {

struct ConsoleDeviceOptions {
    int64_t timeout_ns = 100'000'000; ///< no valid packet for this long = disconnected
    int maxPacketsPerPoll = 64;
    double maxForce = 15.0; ///< N per arm, the console's motors [B §4]
};

class ConsoleDevice final : public Device {
public:
    /// Throws viscera::InputError when the local socket cannot be opened.
    ConsoleDevice(const Endpoint& console, const ConsoleDeviceOptions& options = {});
    const DeviceCapabilities& capabilities() const override { return m_caps; }
    void poll(int64_t now_ns, DeviceState& out) override;
    void send(const DeviceCommand& command) override;
    LinkStats linkStats() const override;
    const char* backend() const override { return "console"; }
    Endpoint localEndpoint() const { return m_socket.local(); }

private:
    struct Counters {
        std::atomic<uint64_t> received{0}, malformed{0}, version{0}, checksum{0}, order{0}, flood{0}, sent{0},
            sendErrors{0}, disconnects{0}, reconnects{0};
    };
    Endpoint m_console;
    ConsoleDeviceOptions m_opt;
    DeviceCapabilities m_caps;
    UdpSocket m_socket;
    Counters m_count;
    DeviceState m_last; ///< newest accepted state
    int64_t m_lastArrival_ns = 0;
    bool m_haveState = false;
    bool m_seqValid = false; ///< sequence order is checked while connected
    bool m_connected = false;
    bool m_everConnected = false;
    uint32_t m_lastSeq = 0;
    uint32_t m_sendSeq = 0;
    alignas(8) uint8_t m_rx[kMaxPacketSize];
    alignas(8) uint8_t m_tx[kMaxPacketSize];
};

} // namespace viscera::haptics
