// The console wire format (version 2): round trips, the MAC (a known answer, the handshake's
// packets, a session key per handshake), and every kind of bad packet (truncated, oversized,
// wrong magic/version/type/size, reserved bits, forged or of another key, non-finite, out of range).
#include "haptics/console_protocol.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <string>
#include <vector>

using namespace viscera::haptics;

namespace {

LinkKey testKey(uint8_t first = 0) {
    LinkKey k{};
    for (size_t i = 0; i < k.size(); ++i)
        k[i] = uint8_t(first + i);
    return k;
}

const LinkMac kMac(testKey());

StatePacket sampleState() {
    StatePacket p;
    p.sequence = 42;
    p.timestamp_ns = 123456789012345;
    p.pedals = kPedalDeadman | kPedalClutch;
    p.arms = 2;
    p.arm[0].measured_cp.position = Vec3(0.1, -0.05, 0.02);
    p.arm[0].measured_cp.orientation = Quat(Eigen::AngleAxisd(0.3, Vec3(0, 0, 1)));
    p.arm[0].jaw_measured_js = 0.4;
    p.arm[0].measured_cv.linear = Vec3(0.01, 0.02, -0.03);
    p.arm[1].measured_cp.position = Vec3(-0.1, 0.05, -0.02);
    p.arm[1].buttons = 5;
    return p;
}

/// Rewrites the MAC after a deliberate change, so only the change is judged.
void reseal(std::vector<uint8_t>& b) {
    kMac.sign(b.data(), b.size() - kLinkTagSize, b.data() + b.size() - kLinkTagSize);
}

std::vector<uint8_t> bytes(const StatePacket& p) {
    std::vector<uint8_t> b(kMaxPacketSize);
    b.resize(encode(p, b.data(), b.size(), kMac));
    return b;
}

void putF32(std::vector<uint8_t>& b, size_t at, float f) {
    std::memcpy(&b[at], &f, 4);
}

} // namespace

TEST(ConsoleProtocol, MacIsTheFirst16BytesOfHmacSha256) {
    // Known answer (Python: hmac.new(bytes(range(32)), msg, hashlib.sha256).hexdigest()[:32]).
    const std::string msg = "viscera console link test vector";
    uint8_t tag[kLinkTagSize];
    kMac.sign(reinterpret_cast<const uint8_t*>(msg.data()), msg.size(), tag);
    const uint8_t expected[kLinkTagSize] = {0xd1, 0x7b, 0x4d, 0x67, 0x6a, 0xd6, 0xd4, 0xa5,
                                            0xdd, 0x30, 0x5f, 0x2c, 0xd2, 0x51, 0x79, 0x62};
    EXPECT_EQ(std::memcmp(tag, expected, kLinkTagSize), 0);
    EXPECT_TRUE(kMac.verify(reinterpret_cast<const uint8_t*>(msg.data()), msg.size(), tag));
    tag[15] ^= 1;
    EXPECT_FALSE(kMac.verify(reinterpret_cast<const uint8_t*>(msg.data()), msg.size(), tag));
    EXPECT_FALSE(LinkMac().verify(reinterpret_cast<const uint8_t*>(msg.data()), msg.size(), expected))
        << "no key, nothing verifies";
}

TEST(ConsoleProtocol, HandshakePacketsAndSessionKeys) {
    HelloPacket h;
    h.sequence = 1;
    h.client = randomNonce();
    std::vector<uint8_t> b(kMaxPacketSize);
    b.resize(encode(h, b.data(), b.size(), kMac));
    ASSERT_EQ(b.size(), kHelloSize);
    EXPECT_EQ(peekType(b.data(), b.size()), uint16_t(PacketType::Hello));
    HelloPacket h2;
    ASSERT_EQ(decode(b.data(), b.size(), h2, kMac), DecodeError::None);
    EXPECT_EQ(h2.client, h.client);
    EXPECT_EQ(decode(b.data(), b.size(), h2, LinkMac(testKey(1))), DecodeError::BadMac) << "another pairing key";
    WelcomePacket w;
    w.client = h.client;
    w.server = randomNonce();
    b.assign(kMaxPacketSize, 0);
    b.resize(encode(w, b.data(), b.size(), kMac));
    ASSERT_EQ(b.size(), kWelcomeSize);
    WelcomePacket w2;
    ASSERT_EQ(decode(b.data(), b.size(), w2, kMac), DecodeError::None);
    EXPECT_EQ(w2.server, w.server);
    EXPECT_NE(h.client, w.server) << "fresh nonces";
    // Both ends derive the same key; another nonce or pairing key gives another.
    const LinkKey k = sessionKey(testKey(), w.client, w.server);
    EXPECT_EQ(sessionKey(testKey(), w2.client, w2.server), k);
    EXPECT_NE(sessionKey(testKey(), w.client, randomNonce()), k);
    EXPECT_NE(sessionKey(testKey(1), w.client, w.server), k);
    // A state of one session does not verify in another.
    std::vector<uint8_t> sb(kMaxPacketSize);
    sb.resize(encode(sampleState(), sb.data(), sb.size(), LinkMac(k)));
    StatePacket q;
    EXPECT_EQ(decode(sb.data(), sb.size(), q, LinkMac(k)), DecodeError::None);
    EXPECT_EQ(decode(sb.data(), sb.size(), q, LinkMac(sessionKey(testKey(), w.client, randomNonce()))),
              DecodeError::BadMac);
}

TEST(ConsoleProtocol, StateRoundTrip) {
    const StatePacket p = sampleState();
    auto b = bytes(p);
    ASSERT_EQ(b.size(), kStateSize);
    EXPECT_EQ(b[0], 'V');
    EXPECT_EQ(b[3], 'N');
    StatePacket q;
    ASSERT_EQ(decode(b.data(), b.size(), q, kMac), DecodeError::None);
    EXPECT_EQ(q.sequence, 42u);
    EXPECT_EQ(q.timestamp_ns, p.timestamp_ns);
    EXPECT_EQ(q.pedals, p.pedals);
    EXPECT_EQ(q.arms, 2);
    EXPECT_TRUE(q.arm[0].measured_cp.position.isApprox(p.arm[0].measured_cp.position, 1e-6));
    EXPECT_TRUE(q.arm[0].measured_cp.orientation.isApprox(p.arm[0].measured_cp.orientation, 1e-6));
    EXPECT_NEAR(q.arm[0].jaw_measured_js, 0.4, 1e-6);
    EXPECT_EQ(q.arm[1].buttons, 5u);
}

TEST(ConsoleProtocol, CommandRoundTrip) {
    CommandPacket p;
    p.sequence = 7;
    p.timestamp_ns = -5;
    p.echoSequence = 41;
    p.flags = kFlagForceEnabled;
    p.arm[0].servo_cf.force = Vec3(1, -2, 3.5);
    p.arm[1].jaw_servo_jf = 0.25;
    std::vector<uint8_t> b(kMaxPacketSize);
    b.resize(encode(p, b.data(), b.size(), kMac));
    ASSERT_EQ(b.size(), kCommandSize);
    CommandPacket q;
    ASSERT_EQ(decode(b.data(), b.size(), q, kMac), DecodeError::None);
    EXPECT_EQ(q.echoSequence, 41u);
    EXPECT_EQ(q.flags, uint32_t(kFlagForceEnabled));
    EXPECT_TRUE(q.arm[0].servo_cf.force.isApprox(Vec3(1, -2, 3.5)));
    EXPECT_FLOAT_EQ(float(q.arm[1].jaw_servo_jf), 0.25f);
    // A command is not a state, and the other way round.
    StatePacket s;
    EXPECT_EQ(decode(b.data(), b.size(), s, kMac), DecodeError::BadType);
}

TEST(ConsoleProtocol, EveryTruncationIsRejected) {
    const auto b = bytes(sampleState());
    for (size_t n = 0; n < b.size(); ++n) {
        StatePacket q;
        const DecodeError e = decode(b.data(), n, q, kMac);
        EXPECT_NE(e, DecodeError::None) << n;
        EXPECT_EQ(e, n < kHeaderSize ? DecodeError::TooShort : DecodeError::BadSize) << n;
    }
    StatePacket q;
    EXPECT_EQ(decode(nullptr, 0, q, kMac), DecodeError::TooShort);
}

TEST(ConsoleProtocol, OversizedAndWrongSizeFieldAreRejected) {
    auto b = bytes(sampleState());
    std::vector<uint8_t> big = b;
    big.resize(kStateSize + 16, 0);
    StatePacket q;
    EXPECT_EQ(decode(big.data(), big.size(), q, kMac), DecodeError::BadSize);
    b[8] = uint8_t(kStateSize - 4); // declared size lies
    EXPECT_EQ(decode(b.data(), b.size(), q, kMac), DecodeError::BadSize);
}

TEST(ConsoleProtocol, WrongMagicVersionTypeReservedAndMac) {
    StatePacket q;
    {
        auto b = bytes(sampleState());
        b[0] = 'X';
        EXPECT_EQ(decode(b.data(), b.size(), q, kMac), DecodeError::BadMagic);
    }
    for (uint16_t v : {0, 1, 3, 255}) {
        auto b = bytes(sampleState());
        b[4] = uint8_t(v);
        b[5] = uint8_t(v >> 8);
        reseal(b);
        EXPECT_EQ(decode(b.data(), b.size(), q, kMac), DecodeError::BadVersion) << v;
    }
    {
        auto b = bytes(sampleState());
        b[6] = 9;
        reseal(b);
        EXPECT_EQ(decode(b.data(), b.size(), q, kMac), DecodeError::BadType);
    }
    {
        auto b = bytes(sampleState());
        b[10] = 1;
        reseal(b);
        EXPECT_EQ(decode(b.data(), b.size(), q, kMac), DecodeError::BadReserved);
    }
    {
        auto b = bytes(sampleState());
        b[40] ^= 0x10; // payload bit flip, MAC left as is
        EXPECT_EQ(decode(b.data(), b.size(), q, kMac), DecodeError::BadMac);
        auto forged = bytes(sampleState());
        LinkMac(testKey(9))
            .sign(forged.data(), forged.size() - kLinkTagSize, forged.data() + forged.size() - kLinkTagSize);
        EXPECT_EQ(decode(forged.data(), forged.size(), q, kMac), DecodeError::BadMac) << "signed with another key";
    }
}

TEST(ConsoleProtocol, OutOfRangeAndNonFiniteFieldsAreRejected) {
    StatePacket q;
    struct Case {
        const char* what;
        size_t offset;
        float value;
    };
    // Offsets: payload at 24: pedals(1) arms(1) reserved(2), arm 0 at 28: pos 28..39, quat 40..55,
    // grip 56, lin vel 60..71, ang vel 72..83.
    const Case cases[] = {{"NaN position", 28, NAN},
                          {"infinite position", 32, INFINITY},
                          {"position beyond 10 m", 36, 11.f},
                          {"zero quaternion w", 40, 0.f},
                          {"NaN grip", 56, NAN},
                          {"negative grip", 56, -0.1f},
                          {"huge velocity", 60, 1e6f}};
    for (const Case& c : cases) {
        auto b = bytes(sampleState());
        if (c.offset == 40) {
            for (size_t k = 40; k < 56; k += 4)
                putF32(b, k, 0.f);
        } else {
            putF32(b, c.offset, c.value);
        }
        reseal(b);
        EXPECT_EQ(decode(b.data(), b.size(), q, kMac), DecodeError::BadField) << c.what;
    }
    auto b = bytes(sampleState());
    b[24] = 0x20; // pedal bit 5 does not exist
    reseal(b);
    EXPECT_EQ(decode(b.data(), b.size(), q, kMac), DecodeError::BadField);
    b = bytes(sampleState());
    b[25] = 3; // three arms
    reseal(b);
    EXPECT_EQ(decode(b.data(), b.size(), q, kMac), DecodeError::BadField);
    // A command with a NaN or a 2 kN force.
    CommandPacket c;
    std::vector<uint8_t> cb(kMaxPacketSize);
    cb.resize(encode(c, cb.data(), cb.size(), kMac));
    putF32(cb, 32, NAN);
    reseal(cb);
    EXPECT_EQ(decode(cb.data(), cb.size(), c, kMac), DecodeError::BadField);
    putF32(cb, 32, 2000.f);
    reseal(cb);
    EXPECT_EQ(decode(cb.data(), cb.size(), c, kMac), DecodeError::BadField);
}

TEST(ConsoleProtocol, RandomBytesNeverDecodeAndNeverCrash) {
    std::mt19937 rng(7);
    std::vector<uint8_t> b(kMaxPacketSize);
    int accepted = 0;
    for (int k = 0; k < 200000; ++k) {
        const size_t n = rng() % b.size();
        for (size_t i = 0; i < n; ++i)
            b[i] = uint8_t(rng());
        if (k % 2 == 0 && n >= 8) { // valid magic and version, to reach the deeper checks
            b[0] = 'V', b[1] = 'S', b[2] = 'C', b[3] = 'N', b[4] = 2, b[5] = 0;
        }
        StatePacket s;
        CommandPacket c;
        accepted += decode(b.data(), n, s, kMac) == DecodeError::None;
        accepted += decode(b.data(), n, c, kMac) == DecodeError::None;
    }
    EXPECT_EQ(accepted, 0);
}

TEST(ConsoleProtocol, SequenceComparisonWraps) {
    EXPECT_TRUE(newer(2, 1));
    EXPECT_FALSE(newer(1, 2));
    EXPECT_FALSE(newer(5, 5));
    EXPECT_TRUE(newer(1, 0xFFFFFFFFu));
}
