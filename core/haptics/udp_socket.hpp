#pragma once
/// A non-blocking IPv4 UDP socket (POSIX). Send and receive never block, allocate or lock, so
/// the servo thread may call them.
#include <netinet/in.h>

#include <cstddef>
#include <cstdint>
#include <string>

namespace viscera::haptics {

struct Endpoint {
    sockaddr_in addr{};
    std::string text() const; ///< "127.0.0.1:7400"
    bool operator==(const Endpoint& o) const {
        return addr.sin_addr.s_addr == o.addr.sin_addr.s_addr && addr.sin_port == o.addr.sin_port;
    }
};

/// Parses "host:port" (IPv4 dotted quad or "localhost"; port 0..65535, 0 only when allowZeroPort).
/// Throws viscera::InputError "<what>: '<text>' ...rule".
Endpoint parseEndpoint(const std::string& text, const std::string& what, bool allowZeroPort = false);

class UdpSocket {
public:
    /// Binds to `local` (port 0: an ephemeral port). receiveBufferBytes bounds the kernel queue so
    /// a flood cannot build a long backlog of stale packets. Throws viscera::InputError naming
    /// the address and the OS error.
    UdpSocket(const Endpoint& local, int receiveBufferBytes = 32768);
    ~UdpSocket();
    UdpSocket(const UdpSocket&) = delete;
    UdpSocket& operator=(const UdpSocket&) = delete;

    /// Bytes received (truncated datagrams report their full length > capacity), or -1 when
    /// nothing is waiting. `from` may be null. `queued_ns` (may be null) gets how long the
    /// datagram waited in the kernel queue (its arrival stamp, SO_TIMESTAMPNS, against now;
    /// 0 when the kernel gave no stamp), so a reader that was descheduled can tell old packets
    /// from fresh ones on its own clock. Linux turns arrival stamping on shortly after the first
    /// socket asks for it (a deferred switch): packets that arrive before then read age 0.
    long receive(uint8_t* buffer, size_t capacity, Endpoint* from, int64_t* queued_ns = nullptr) noexcept;
    bool sendTo(const uint8_t* data, size_t size, const Endpoint& to) noexcept;
    /// Waits up to timeout_ms for a datagram (not for the servo thread). True when one waits.
    bool wait(int timeout_ms) noexcept;
    Endpoint local() const;
    int fd() const { return m_fd; }

private:
    int m_fd = -1;
};

} // namespace viscera::haptics
