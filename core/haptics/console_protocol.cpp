#include "haptics/console_protocol.hpp"

#include <array>
#include <cmath>
#include <cstring>

namespace viscera::haptics {
namespace {

class Writer {
public:
    explicit Writer(uint8_t* p) : m_p(p) {}
    void u8(uint8_t v) { m_p[m_n++] = v; }
    void u16(uint16_t v) {
        for (int k = 0; k < 2; ++k)
            u8(uint8_t(v >> (8 * k)));
    }
    void u32(uint32_t v) {
        for (int k = 0; k < 4; ++k)
            u8(uint8_t(v >> (8 * k)));
    }
    void i64(int64_t v) {
        for (int k = 0; k < 8; ++k)
            u8(uint8_t(uint64_t(v) >> (8 * k)));
    }
    void f32(double v) {
        float f = static_cast<float>(v);
        uint32_t b;
        std::memcpy(&b, &f, 4);
        u32(b);
    }
    void vec3(const Vec3& v) {
        f32(v.x());
        f32(v.y());
        f32(v.z());
    }
    void bytes(const uint8_t* in, size_t n) {
        for (size_t k = 0; k < n; ++k)
            u8(in[k]);
    }
    /// Appends the MAC of everything written so far; returns the packet's size.
    size_t seal(const LinkMac& mac) {
        mac.sign(m_p, m_n, m_p + m_n);
        m_n += kLinkTagSize;
        return m_n;
    }
    size_t size() const { return m_n; }
    uint8_t* data() const { return m_p; }

private:
    uint8_t* m_p;
    size_t m_n = 0;
};

class Reader {
public:
    explicit Reader(const uint8_t* p) : m_p(p) {}
    uint8_t u8() { return m_p[m_n++]; }
    uint16_t u16() {
        uint16_t v = 0;
        for (int k = 0; k < 2; ++k)
            v |= uint16_t(u8()) << (8 * k);
        return v;
    }
    uint32_t u32() {
        uint32_t v = 0;
        for (int k = 0; k < 4; ++k)
            v |= uint32_t(u8()) << (8 * k);
        return v;
    }
    int64_t i64() {
        uint64_t v = 0;
        for (int k = 0; k < 8; ++k)
            v |= uint64_t(u8()) << (8 * k);
        return int64_t(v);
    }
    /// Reads a binary32; clears ok when it is not finite.
    double f32(bool& ok) {
        uint32_t b = u32();
        float f;
        std::memcpy(&f, &b, 4);
        if (!std::isfinite(f)) ok = false;
        return f;
    }
    Vec3 vec3(bool& ok) {
        double x = f32(ok), y = f32(ok), z = f32(ok);
        return {x, y, z};
    }
    void bytes(uint8_t* out, size_t n) {
        for (size_t k = 0; k < n; ++k)
            out[k] = u8();
    }
    void skip(size_t n) { m_n += n; }
    size_t offset() const { return m_n; }

private:
    const uint8_t* m_p;
    size_t m_n = 0;
};

void header(Writer& w, PacketType type, uint16_t size, uint32_t seq, int64_t ts) {
    w.u32(kMagic);
    w.u16(kVersion);
    w.u16(static_cast<uint16_t>(type));
    w.u16(size);
    w.u16(0);
    w.u32(seq);
    w.i64(ts);
}

/// Checks the header and the MAC trailer; on success the reader stands after the header.
DecodeError checkFrame(const uint8_t* data, size_t size, PacketType type, size_t expected, const LinkMac& mac,
                       Reader& r, uint32_t& seq, int64_t& ts) {
    if (data == nullptr || size < kHeaderSize) return DecodeError::TooShort;
    if (r.u32() != kMagic) return DecodeError::BadMagic;
    if (r.u16() != kVersion) return DecodeError::BadVersion;
    if (r.u16() != static_cast<uint16_t>(type)) return DecodeError::BadType;
    const uint16_t declared = r.u16();
    if (declared != expected || size != expected) return DecodeError::BadSize;
    if (r.u16() != 0) return DecodeError::BadReserved;
    seq = r.u32();
    ts = r.i64();
    if (!mac.verify(data, expected - kLinkTagSize, data + expected - kLinkTagSize)) return DecodeError::BadMac;
    return DecodeError::None;
}

/// The frame checks of `type`, then body(reader, packet) for the payload; `out` is written only
/// when both pass.
template <class Packet, class Body>
DecodeError decodePacket(const uint8_t* data, size_t size, PacketType type, size_t expected, const LinkMac& mac,
                         Packet& out, const Body& body) {
    Reader r(data);
    Packet p;
    if (auto e = checkFrame(data, size, type, expected, mac, r, p.sequence, p.timestamp_ns); e != DecodeError::None)
        return e;
    if (auto e = body(r, p); e != DecodeError::None) return e;
    out = p;
    return DecodeError::None;
}

} // namespace

const char* decodeErrorName(DecodeError e) {
    switch (e) {
    case DecodeError::None:
        return "ok";
    case DecodeError::TooShort:
        return "shorter than the header";
    case DecodeError::BadMagic:
        return "bad magic";
    case DecodeError::BadVersion:
        return "unsupported protocol version";
    case DecodeError::BadType:
        return "unexpected packet type";
    case DecodeError::BadSize:
        return "size does not match the packet type";
    case DecodeError::BadReserved:
        return "reserved field not zero";
    case DecodeError::BadMac:
        return "authentication failed (MAC mismatch)";
    case DecodeError::BadField:
        return "field out of range";
    }
    return "?";
}

uint16_t peekType(const uint8_t* data, size_t size) {
    if (data == nullptr || size < kHeaderSize) return 0;
    Reader r(data);
    if (r.u32() != kMagic || r.u16() != kVersion) return 0;
    return r.u16();
}

size_t encode(const StatePacket& p, uint8_t* out, size_t capacity, const LinkMac& mac) {
    if (capacity < kStateSize) return 0;
    Writer w(out);
    header(w, PacketType::State, kStateSize, p.sequence, p.timestamp_ns);
    w.u8(static_cast<uint8_t>(p.pedals & kPedalMask));
    w.u8(p.arms);
    w.u16(0);
    for (const ArmState& a : p.arm) {
        w.vec3(a.measured_cp.position);
        const Quat& q = a.measured_cp.orientation;
        w.f32(q.w());
        w.f32(q.x());
        w.f32(q.y());
        w.f32(q.z());
        w.f32(a.jaw_measured_js);
        w.vec3(a.measured_cv.linear);
        w.vec3(a.measured_cv.angular);
        w.u32(a.buttons);
        w.u32(0);
    }
    return w.seal(mac);
}

size_t encode(const CommandPacket& p, uint8_t* out, size_t capacity, const LinkMac& mac) {
    if (capacity < kCommandSize) return 0;
    Writer w(out);
    header(w, PacketType::Command, kCommandSize, p.sequence, p.timestamp_ns);
    w.u32(p.echoSequence);
    w.u32(p.flags);
    for (const ArmCommand& a : p.arm) {
        w.vec3(a.servo_cf.force);
        w.vec3(a.servo_cf.torque);
        w.f32(a.jaw_servo_jf);
        w.u32(0);
    }
    return w.seal(mac);
}

DecodeError decode(const uint8_t* data, size_t size, StatePacket& out, const LinkMac& mac) {
    return decodePacket(data, size, PacketType::State, kStateSize, mac, out, [](Reader& r, StatePacket& p) {
        p.pedals = r.u8();
        p.arms = r.u8();
        if (r.u16() != 0) return DecodeError::BadReserved;
        if (p.pedals > kPedalMask || p.arms < 1 || p.arms > kMaxArms) return DecodeError::BadField;
        bool ok = true;
        for (ArmState& a : p.arm) {
            a.measured_cp.position = r.vec3(ok);
            double w = r.f32(ok), x = r.f32(ok), y = r.f32(ok), z = r.f32(ok);
            Quat q(w, x, y, z);
            a.jaw_measured_js = r.f32(ok);
            a.measured_cv.linear = r.vec3(ok);
            a.measured_cv.angular = r.vec3(ok);
            a.buttons = r.u32();
            if (r.u32() != 0) return DecodeError::BadReserved;
            if (!ok) return DecodeError::BadField;
            const double n = q.norm();
            if (!(n > 0.9 && n < 1.1)) return DecodeError::BadField;
            a.measured_cp.orientation = q.normalized();
            if (a.measured_cp.position.cwiseAbs().maxCoeff() > 10.0 || a.jaw_measured_js < 0 ||
                a.jaw_measured_js > M_PI || a.measured_cv.linear.cwiseAbs().maxCoeff() > 100.0 ||
                a.measured_cv.angular.cwiseAbs().maxCoeff() > 1000.0)
                return DecodeError::BadField;
        }
        return DecodeError::None;
    });
}

DecodeError decode(const uint8_t* data, size_t size, CommandPacket& out, const LinkMac& mac) {
    return decodePacket(data, size, PacketType::Command, kCommandSize, mac, out, [](Reader& r, CommandPacket& p) {
        p.echoSequence = r.u32();
        p.flags = r.u32();
        bool ok = true;
        for (ArmCommand& a : p.arm) {
            a.servo_cf.force = r.vec3(ok);
            a.servo_cf.torque = r.vec3(ok);
            a.jaw_servo_jf = r.f32(ok);
            if (r.u32() != 0) return DecodeError::BadReserved;
            if (!ok) return DecodeError::BadField;
            if (a.servo_cf.force.norm() > kMaxWireForce || a.servo_cf.torque.norm() > kMaxWireForce ||
                std::abs(a.jaw_servo_jf) > kMaxWireForce)
                return DecodeError::BadField;
        }
        return DecodeError::None;
    });
}

size_t encode(const HelloPacket& p, uint8_t* out, size_t capacity, const LinkMac& mac) {
    if (capacity < kHelloSize) return 0;
    Writer w(out);
    header(w, PacketType::Hello, kHelloSize, p.sequence, p.timestamp_ns);
    w.bytes(p.client.data(), kNonceSize);
    return w.seal(mac);
}

size_t encode(const WelcomePacket& p, uint8_t* out, size_t capacity, const LinkMac& mac) {
    if (capacity < kWelcomeSize) return 0;
    Writer w(out);
    header(w, PacketType::Welcome, kWelcomeSize, p.sequence, p.timestamp_ns);
    w.bytes(p.client.data(), kNonceSize);
    w.bytes(p.server.data(), kNonceSize);
    return w.seal(mac);
}

DecodeError decode(const uint8_t* data, size_t size, HelloPacket& out, const LinkMac& mac) {
    return decodePacket(data, size, PacketType::Hello, kHelloSize, mac, out, [](Reader& r, HelloPacket& p) {
        r.bytes(p.client.data(), kNonceSize);
        return DecodeError::None;
    });
}

DecodeError decode(const uint8_t* data, size_t size, WelcomePacket& out, const LinkMac& mac) {
    return decodePacket(data, size, PacketType::Welcome, kWelcomeSize, mac, out, [](Reader& r, WelcomePacket& p) {
        r.bytes(p.client.data(), kNonceSize);
        r.bytes(p.server.data(), kNonceSize);
        return DecodeError::None;
    });
}

} // namespace viscera::haptics
