#include "haptics/console_device.hpp"

namespace viscera::haptics {

ConsoleDevice::ConsoleDevice(const Endpoint& console, const ConsoleDeviceOptions& options)
    : m_console(console), m_opt(options), m_socket([] {
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
        if (!(from == m_console) || n > static_cast<long>(sizeof m_rx)) {
            m_count.malformed.fetch_add(1, std::memory_order_relaxed);
            continue;
        }
        const DecodeError e = decode(m_rx, static_cast<size_t>(n), pkt);
        if (e == DecodeError::BadVersion) {
            m_count.version.fetch_add(1, std::memory_order_relaxed);
            continue;
        }
        if (e == DecodeError::BadChecksum) {
            m_count.checksum.fetch_add(1, std::memory_order_relaxed);
            continue;
        }
        if (e != DecodeError::None) {
            m_count.malformed.fetch_add(1, std::memory_order_relaxed);
            continue;
        }
        // After a disconnect the console may have restarted its sequence: accept any number then.
        if (m_seqValid && !newer(pkt.sequence, m_lastSeq)) {
            m_count.order.fetch_add(1, std::memory_order_relaxed);
            continue;
        }
        if (fresh) m_count.flood.fetch_add(1, std::memory_order_relaxed);
        fresh = true;
        m_haveState = true;
        m_seqValid = true;
        m_lastSeq = pkt.sequence;
        // Arrival on this poll's clock: a servo tick that ran late must not take a packet that
        // waited in the queue for a fresh one (the device timeout counts from the arrival).
        m_lastArrival_ns = now_ns - queued;
        m_last.timestamp_ns = m_lastArrival_ns;
        m_last.sequence += 1;
        m_last.pedals = pkt.pedals;
        for (int a = 0; a < kMaxArms; ++a)
            m_last.arms[a] = pkt.arm[a];
        m_count.received.fetch_add(1, std::memory_order_relaxed);
    }
    const bool connected = m_haveState && now_ns - m_lastArrival_ns <= m_opt.timeout_ns;
    if (!connected) m_seqValid = false;
    if (m_connected && !connected) m_count.disconnects.fetch_add(1, std::memory_order_relaxed);
    if (!m_connected && connected) {
        if (m_everConnected) m_count.reconnects.fetch_add(1, std::memory_order_relaxed);
        m_everConnected = true;
    }
    m_connected = connected;
    out = m_last;
    out.connected = connected;
}

void ConsoleDevice::send(const DeviceCommand& command) {
    CommandPacket p;
    p.sequence = ++m_sendSeq;
    p.timestamp_ns = command.timestamp_ns;
    p.echoSequence = m_lastSeq;
    p.flags = command.flags;
    p.arm = command.arms;
    const size_t n = encode(p, m_tx, sizeof m_tx);
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
    s.rejectedChecksum = r(m_count.checksum);
    s.rejectedOrder = r(m_count.order);
    s.droppedFlood = r(m_count.flood);
    s.sent = r(m_count.sent);
    s.sendErrors = r(m_count.sendErrors);
    s.disconnects = r(m_count.disconnects);
    s.reconnects = r(m_count.reconnects);
    return s;
}

} // namespace viscera::haptics
