#include "haptics/udp_socket.hpp"

#include "sim/util/error.hpp"

#include <arpa/inet.h>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <poll.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

namespace viscera::haptics {

std::string Endpoint::text() const {
    char ip[INET_ADDRSTRLEN] = {};
    inet_ntop(AF_INET, &addr.sin_addr, ip, sizeof ip);
    return std::string(ip) + ":" + std::to_string(ntohs(addr.sin_port));
}

Endpoint parseEndpoint(const std::string& text, const std::string& what, bool allowZeroPort) {
    const size_t colon = text.rfind(':');
    if (colon == std::string::npos || colon == 0 || colon + 1 >= text.size())
        throw InputError(what + ": '" + text + "' must be host:port (e.g. 127.0.0.1:7400)");
    std::string host = text.substr(0, colon);
    const std::string port = text.substr(colon + 1);
    char* end = nullptr;
    const long p = std::strtol(port.c_str(), &end, 10);
    if (*end != '\0' || p < (allowZeroPort ? 0 : 1) || p > 65535)
        throw InputError(what + ": port '" + port + "' must be an integer in [" + (allowZeroPort ? "0" : "1") +
                         ", 65535]");
    if (host == "localhost") host = "127.0.0.1";
    Endpoint e;
    e.addr.sin_family = AF_INET;
    e.addr.sin_port = htons(static_cast<uint16_t>(p));
    if (inet_pton(AF_INET, host.c_str(), &e.addr.sin_addr) != 1)
        throw InputError(what + ": host '" + host + "' must be an IPv4 address (e.g. 127.0.0.1) or localhost");
    return e;
}

UdpSocket::UdpSocket(const Endpoint& local, int receiveBufferBytes) {
    m_fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    if (m_fd < 0) throw InputError("udp " + local.text() + ": socket(): " + std::strerror(errno));
    if (receiveBufferBytes > 0)
        ::setsockopt(m_fd, SOL_SOCKET, SO_RCVBUF, &receiveBufferBytes, sizeof receiveBufferBytes);
    // Arrival stamps for the queue age receive() reports; without them the age reads 0.
    const int on = 1;
    ::setsockopt(m_fd, SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on);
    if (::bind(m_fd, reinterpret_cast<const sockaddr*>(&local.addr), sizeof local.addr) != 0) {
        const int err = errno;
        ::close(m_fd);
        m_fd = -1;
        throw InputError("udp " + local.text() + ": cannot bind: " + std::strerror(err));
    }
}

UdpSocket::~UdpSocket() {
    if (m_fd >= 0) ::close(m_fd);
}

long UdpSocket::receive(uint8_t* buffer, size_t capacity, Endpoint* from, int64_t* queued_ns) noexcept {
    sockaddr_in src{};
    iovec iov{buffer, capacity};
    alignas(cmsghdr) uint8_t control[CMSG_SPACE(sizeof(timespec))];
    msghdr msg{};
    msg.msg_name = &src;
    msg.msg_namelen = sizeof src;
    msg.msg_iov = &iov;
    msg.msg_iovlen = 1;
    msg.msg_control = control;
    msg.msg_controllen = sizeof control;
    const ssize_t n = ::recvmsg(m_fd, &msg, MSG_DONTWAIT | MSG_TRUNC);
    if (n < 0) return -1;
    if (from) from->addr = src;
    if (queued_ns) {
        *queued_ns = 0;
        for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c; c = CMSG_NXTHDR(&msg, c)) {
            if (c->cmsg_level != SOL_SOCKET || c->cmsg_type != SCM_TIMESTAMPNS) continue;
            timespec stamp{}, now{};
            std::memcpy(&stamp, CMSG_DATA(c), sizeof stamp);
            clock_gettime(CLOCK_REALTIME, &now); // the kernel stamps on the realtime clock
            const int64_t age = (int64_t(now.tv_sec) - stamp.tv_sec) * 1'000'000'000 + (now.tv_nsec - stamp.tv_nsec);
            *queued_ns = age > 0 ? age : 0; // a realtime step backwards reads as no wait
        }
    }
    return static_cast<long>(n);
}

bool UdpSocket::sendTo(const uint8_t* data, size_t size, const Endpoint& to) noexcept {
    const ssize_t n = ::sendto(m_fd, data, size, MSG_DONTWAIT | MSG_NOSIGNAL,
                               reinterpret_cast<const sockaddr*>(&to.addr), sizeof to.addr);
    return n == static_cast<ssize_t>(size);
}

bool UdpSocket::wait(int timeout_ms) noexcept {
    pollfd p{m_fd, POLLIN, 0};
    return ::poll(&p, 1, timeout_ms) > 0;
}

Endpoint UdpSocket::local() const {
    Endpoint e;
    socklen_t len = sizeof e.addr;
    ::getsockname(m_fd, reinterpret_cast<sockaddr*>(&e.addr), &len);
    return e;
}

} // namespace viscera::haptics
