#include "haptics/console_device.hpp"

#include <algorithm>

namespace viscera::haptics {

ConsoleDevice::ConsoleDevice(const Endpoint& console, const ConsoleDeviceOptions& options)
    : m_console(console), m_opt(options), m_pairing(options.pairingKey), m_socket([] {
          Endpoint any;
          any.addr.sin_family = AF_INET;
          any.addr.sin_addr.s_addr = htonl(INADDR_ANY);
          any.addr.sin_port = 0;
          return any;
      }()) {
    m_caps.name = "console " + console.text();
    m_caps.arms = 2;
    m_caps.arm[0].hand = Hand::Left;
    m_caps.arm[1].hand = Hand::Right;
    for (auto& a : m_caps.arm) {
        a.dof = 7;
        a.grip = true;
        a.maxForce = options.maxForce;
    }
    m_caps.pedals = 5;
    m_caps.realtime = true;
}

void ConsoleDevice::poll(int64_t now_ns, DeviceState& out) {
    bool fresh = false;
    StatePacket pkt;
    for (int k = 0; k < m_opt.maxPacketsPerPoll; ++k) {
        Endpoint from;
        int64_t queued = 0;
        const long n = m_socket.receive(m_rx, sizeof m_rx, &from, &queued);
        if (n < 0) break;
        if (!(from == m_console)) { // the console's address is the only one read
            m_count.peer.fetch_add(1, std::memory_order_relaxed);
            continue;
        }
        if (n > static_cast<long>(sizeof m_rx)) {
            m_count.malformed.fetch_add(1, std::memory_order_relaxed);
            continue;
        }
        if (!take(m_rx, static_cast<size_t>(n), pkt, now_ns - queued)) continue;
        if (fresh) m_count.flood.fetch_add(1, std::memory_order_relaxed);
        fresh = true;
        m_haveState = true;
        m_seqValid = true;
        m_lastSeq = pkt.sequence;
        // Arrival on this poll's clock: a servo tick that ran late must not take a packet that
        // waited in the queue for a fresh one (the device timeout counts from the arrival).
        m_lastArrival_ns = m_lastLife_ns = now_ns - queued;
        m_last.timestamp_ns = m_lastArrival_ns;
        m_last.sequence += 1;
        m_last.pedals = pkt.pedals;
        for (int a = 0; a < kMaxArms; ++a)
            m_last.arms[a] = pkt.arm[a];
        m_count.received.fetch_add(1, std::memory_order_relaxed);
    }
    const bool connected = m_haveState && now_ns - m_lastArrival_ns <= m_opt.timeout_ns;
    // Nothing valid for the timeout since the last state or welcome: hellos again (a restarted
    // console); states of the old session still count meanwhile.
    if (now_ns - m_lastLife_ns > m_opt.timeout_ns) m_wantSession = true;
    if (m_connected && !connected) m_count.disconnects.fetch_add(1, std::memory_order_relaxed);
    if (!m_connected && connected) {
        if (m_everConnected) m_count.reconnects.fetch_add(1, std::memory_order_relaxed);
        m_everConnected = true;
    }
    m_connected = connected;
    out = m_last;
    out.connected = connected;
}

bool ConsoleDevice::take(const uint8_t* data, size_t size, StatePacket& pkt, int64_t arrived_ns) {
    auto refuse = [&](DecodeError e) {
        auto& c = e == DecodeError::BadVersion ? m_count.version
                  : e == DecodeError::BadMac   ? m_count.auth
                                               : m_count.malformed;
        c.fetch_add(1, std::memory_order_relaxed);
        return false;
    };
    if (peekType(data, size) == static_cast<uint16_t>(PacketType::Welcome)) {
        WelcomePacket w;
        if (const DecodeError e = decode(data, size, w, m_pairing); e != DecodeError::None) return refuse(e);
        const auto end = m_pending.begin() + static_cast<std::ptrdiff_t>(m_pendingCount);
        if (!m_helloSent || std::find(m_pending.begin(), end, w.client) == end) { // an old or replayed welcome
            m_count.staleWelcome.fetch_add(1, std::memory_order_relaxed);
            return false;
        }
        m_session.setKey(sessionKey(m_pairing, w.client, w.server)); // no allocation: servo thread
        m_helloSent = false;
        m_pendingCount = m_pendingNext = 0; // the pending nonces fill [0, count) again
        m_wantSession = false;
        m_seqValid = false; // a new session numbers its states afresh
        m_lastLife_ns = arrived_ns;
        m_count.handshakes.fetch_add(1, std::memory_order_relaxed);
        return false;
    }
    // Without a session every state fails its MAC (counted as authentication).
    if (const DecodeError e = decode(data, size, pkt, m_session); e != DecodeError::None) return refuse(e);
    if (m_seqValid && !newer(pkt.sequence, m_lastSeq)) { // a replay, a duplicate or late
        m_count.order.fetch_add(1, std::memory_order_relaxed);
        return false;
    }
    if (m_seqValid && uint32_t(pkt.sequence - m_lastSeq) > kMaxSequenceJump) {
        m_count.jump.fetch_add(1, std::memory_order_relaxed);
        return false;
    }
    return true;
}

void ConsoleDevice::sendHello(int64_t now_ns) {
    HelloPacket h;
    h.sequence = ++m_sendSeq;
    h.timestamp_ns = now_ns;
    h.client = m_nonces.next();
    m_pending[m_pendingNext] = h.client;
    m_pendingNext = (m_pendingNext + 1) % kPendingHellos;
    m_pendingCount = std::min(m_pendingCount + 1, kPendingHellos);
    const size_t n = encode(h, m_tx, sizeof m_tx, m_pairing);
    m_helloSent = true;
    m_lastHello_ns = now_ns;
    if (!m_socket.sendTo(m_tx, n, m_console)) m_count.sendErrors.fetch_add(1, std::memory_order_relaxed);
}

void ConsoleDevice::send(const DeviceCommand& command) {
    if (m_wantSession && (!m_helloSent || command.timestamp_ns - m_lastHello_ns >= m_opt.helloInterval_ns))
        sendHello(command.timestamp_ns);
    if (!m_session.hasKey()) return; // no session yet: only hellos go out
    CommandPacket p;
    p.sequence = ++m_sendSeq;
    p.timestamp_ns = command.timestamp_ns;
    p.echoSequence = m_lastSeq;
    p.flags = command.flags;
    p.arm = command.arms;
    const size_t n = encode(p, m_tx, sizeof m_tx, m_session);
    if (m_socket.sendTo(m_tx, n, m_console))
        m_count.sent.fetch_add(1, std::memory_order_relaxed);
    else
        m_count.sendErrors.fetch_add(1, std::memory_order_relaxed);
}

LinkStats ConsoleDevice::linkStats() const {
    LinkStats s;
    auto r = [](const std::atomic<uint64_t>& a) { return a.load(std::memory_order_relaxed); };
    s.received = r(m_count.received);
    s.rejectedMalformed = r(m_count.malformed);
    s.rejectedVersion = r(m_count.version);
    s.rejectedAuth = r(m_count.auth);
    s.rejectedOrder = r(m_count.order);
    s.rejectedJump = r(m_count.jump);
    s.rejectedPeer = r(m_count.peer);
    s.staleWelcomes = r(m_count.staleWelcome);
    s.handshakes = r(m_count.handshakes);
    s.droppedFlood = r(m_count.flood);
    s.sent = r(m_count.sent);
    s.sendErrors = r(m_count.sendErrors);
    s.disconnects = r(m_count.disconnects);
    s.reconnects = r(m_count.reconnects);
    return s;
}

} // namespace viscera::haptics
