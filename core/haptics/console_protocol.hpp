#pragma once
/// Wire format of the bimanual console link (UDP), version 2. Spec: packaging/console-protocol.md.
///
/// Every packet: a 24-byte header, a fixed payload for its type, a 16-byte MAC trailer
/// (HMAC-SHA256 of everything before it, link_auth.hpp): the handshake's hello and welcome under
/// the pairing key, states and commands under the session key the handshake made. All integers
/// little-endian, all reals IEEE-754 binary32 little-endian. Decoding checks, in order: length
/// ≥ header, magic, version, type, declared size = received size = the type's size, reserved
/// fields zero, the MAC, then every field's range (finite reals, unit quaternion within 10%,
/// pedals ≤ 31, forces ≤ 1 kN). Allocation-free; never reads outside [data, data + size).
#include "haptics/link_auth.hpp"
#include "haptics/types.hpp"

#include <cstddef>
#include <cstdint>

namespace viscera::haptics {

constexpr uint32_t kMagic = 0x4E435356u; ///< bytes 'V' 'S' 'C' 'N'
constexpr uint16_t kVersion = 2;
constexpr size_t kHeaderSize = 24;
constexpr size_t kStateSize = 172;
constexpr size_t kCommandSize = 112;
constexpr size_t kHelloSize = kHeaderSize + kNonceSize + kLinkTagSize;
constexpr size_t kWelcomeSize = kHeaderSize + 2 * kNonceSize + kLinkTagSize;
/// A state or command more than this many sequence numbers ahead of the last accepted one of its
/// session is refused (a jump: 1 s of packets at 1 kHz; a longer gap ends in a new handshake).
constexpr uint32_t kMaxSequenceJump = 1000;
constexpr size_t kMaxPacketSize = 512;    ///< receive buffers; larger datagrams are malformed
constexpr double kMaxWireForce = 1000.0;  ///< N; a command beyond is malformed
constexpr double kConsoleMaxForce = 15.0; ///< N per arm: the console's motors [B §4]; it clamps commands to this

enum class PacketType : uint16_t { State = 1, Command = 2, Hello = 3, Welcome = 4 };

/// Console → player: both masters and the pedals at one instant.
struct StatePacket {
    uint32_t sequence = 0;
    int64_t timestamp_ns = 0; ///< console clock
    uint32_t pedals = 0;      ///< Pedal bits
    uint8_t arms = 2;         ///< 1 or 2
    std::array<ArmState, kMaxArms> arm{};
};

/// Player → console: the forces to render (already through the safety filter).
struct CommandPacket {
    uint32_t sequence = 0;
    int64_t timestamp_ns = 0;  ///< player clock
    uint32_t echoSequence = 0; ///< newest state sequence the player had received
    uint32_t flags = 0;        ///< CommandFlag bits
    std::array<ArmCommand, kMaxArms> arm{};
};

/// Player → console: opens a session (under the pairing key).
struct HelloPacket {
    uint32_t sequence = 0;
    int64_t timestamp_ns = 0;
    Nonce client{};
};

/// Console → player: accepts a hello; the session key is sessionKey(pairing, client, server).
struct WelcomePacket {
    uint32_t sequence = 0;
    int64_t timestamp_ns = 0;
    Nonce client{}; ///< the hello's
    Nonce server{};
};

enum class DecodeError : uint8_t {
    None,
    TooShort,
    BadMagic,
    BadVersion,
    BadType,
    BadSize,
    BadReserved,
    BadMac,
    BadField
};
const char* decodeErrorName(DecodeError e);

/// Write the packet into out (capacity ≥ the type's size), its MAC made with `mac`; returns the
/// byte count (0 when the capacity is too small).
size_t encode(const StatePacket& p, uint8_t* out, size_t capacity, const LinkMac& mac);
size_t encode(const CommandPacket& p, uint8_t* out, size_t capacity, const LinkMac& mac);
size_t encode(const HelloPacket& p, uint8_t* out, size_t capacity, const LinkMac& mac);
size_t encode(const WelcomePacket& p, uint8_t* out, size_t capacity, const LinkMac& mac);
/// Decode, the MAC checked with `mac`; `out` is only written when the result is DecodeError::None.
DecodeError decode(const uint8_t* data, size_t size, StatePacket& out, const LinkMac& mac);
DecodeError decode(const uint8_t* data, size_t size, CommandPacket& out, const LinkMac& mac);
DecodeError decode(const uint8_t* data, size_t size, HelloPacket& out, const LinkMac& mac);
DecodeError decode(const uint8_t* data, size_t size, WelcomePacket& out, const LinkMac& mac);
/// The type field of a packet with this build's magic and version (to pick the decoder); 0
/// otherwise.
uint16_t peekType(const uint8_t* data, size_t size);

/// True when `a` is newer than `b` in 32-bit serial-number arithmetic (RFC 1982).
inline bool newer(uint32_t a, uint32_t b) {
    return a != b && uint32_t(a - b) < 0x80000000u;
}

} // namespace viscera::haptics
