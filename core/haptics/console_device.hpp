#pragma once
/// Network backend for the bimanual console (2 × 7-DOF masters with grip, 5 pedals, [B §4]) over
/// UDP, protocol version 2 (console_protocol.hpp, packaging/console-protocol.md).
///
/// The player binds an ephemeral local port and opens a session: a hello under the pairing key
/// (every helloInterval until a valid welcome answers it), then a command packet every servo
/// tick under the session key; the console answers with state packets. Only packets from the
/// console's address are read (others count as peer). poll() drains at most maxPacketsPerPoll
/// datagrams per tick and keeps the newest valid state; malformed, wrong-version, forged (MAC),
/// replayed (not newer), jumped and foreign packets are counted by reason and move nothing.
/// With no valid state for `timeout`, the device reports disconnected (the safety filter then
/// zeroes the force) and sends hellos again; states of the old session still reconnect it until
/// a welcome opens a new one (a restarted console).
#include "haptics/console_protocol.hpp"
#include "haptics/device.hpp"
#include "haptics/udp_socket.hpp"

#include <array>
#include <atomic>
#include <memory>

namespace viscera::haptics {

struct ConsoleDeviceOptions {
    LinkKey pairingKey{}; ///< shared with the console (loadPairingKey)
    int64_t helloInterval_ns = 50'000'000;
    int64_t timeout_ns = 100'000'000; ///< no valid packet for this long = disconnected
    int maxPacketsPerPoll = 64;
    double maxForce = kConsoleMaxForce; ///< N per arm, the console's motors
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
        std::atomic<uint64_t> received{0}, malformed{0}, version{0}, auth{0}, order{0}, jump{0}, peer{0},
            staleWelcome{0}, flood{0}, sent{0}, sendErrors{0}, disconnects{0}, reconnects{0}, handshakes{0};
    };
    /// One datagram of the console's: a welcome (opens the session) or a state; true when it was
    /// a valid state (then in pkt).
    bool take(const uint8_t* data, size_t size, StatePacket& pkt, int64_t arrived_ns);
    void sendHello(int64_t now_ns);
    Endpoint m_console;
    ConsoleDeviceOptions m_opt;
    LinkMac m_pairing, m_session; ///< MACs under the pairing key (handshake) and the session key
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
    /// Client nonces of the hellos still unanswered (the newest kPendingHellos): a welcome for any
    /// of them opens the session, so a round trip longer than the hello interval still connects.
    static constexpr size_t kPendingHellos = 4;
    std::array<Nonce, kPendingHellos> m_pending{};
    size_t m_pendingCount = 0, m_pendingNext = 0;
    NonceSource m_nonces;
    bool m_helloSent = false;  ///< a hello went out that no welcome answered yet
    bool m_wantSession = true; ///< no session, or the link timed out: hellos go out
    int64_t m_lastHello_ns = 0;
    int64_t m_lastLife_ns = 0; ///< arrival of the last valid state or welcome
    alignas(8) uint8_t m_rx[kMaxPacketSize];
    alignas(8) uint8_t m_tx[kMaxPacketSize];
};

} // namespace viscera::haptics
