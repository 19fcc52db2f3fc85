#pragma once
/// Wire format of the bimanual console link (UDP), version 1. Spec: packaging/console-protocol.md.
///
/// Every packet: a 24-byte header, a fixed payload for its type, a CRC-32 trailer. All integers
/// little-endian, all reals IEEE-754 binary32 little-endian. Decoding checks, in order: length
/// ≥ header, magic, version, type, declared size = received size = the type's size, reserved
/// fields zero, CRC-32, then every field's range (finite reals, unit quaternion within 10%,
/// pedals ≤ 31, forces ≤ 1 kN). Allocation-free; never reads outside [data, data + size).
#include "haptics/types.hpp"

#include <cstddef>
#include <cstdint>

namespace viscera::haptics {

constexpr uint32_t kMagic = 0x4E435356u; ///< bytes 'V' 'S' 'C' 'N'
constexpr uint16_t kVersion = 1;
constexpr size_t kHeaderSize = 24;
constexpr size_t kStateSize = 160;
constexpr size_t kCommandSize = 100;
constexpr size_t kMaxPacketSize = 512;   ///< receive buffers; larger datagrams are malformed
constexpr double kMaxWireForce = 1000.0; ///< N; a command beyond is malformed

enum class PacketType : uint16_t { State = 1, Command = 2 };

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

enum class DecodeError : uint8_t {
    None,
    TooShort,
    BadMagic,
    BadVersion,
    BadType,
    BadSize,
    BadReserved,
    BadChecksum,
    BadField
};
const char* decodeErrorName(DecodeError e);

/// Write the packet into out (capacity ≥ the type's size); returns the byte count.
size_t encode(const StatePacket& p, uint8_t* out, size_t capacity);
size_t encode(const CommandPacket& p, uint8_t* out, size_t capacity);
/// Decode; `out` is only written when the result is DecodeError::None.
DecodeError decode(const uint8_t* data, size_t size, StatePacket& out);
DecodeError decode(const uint8_t* data, size_t size, CommandPacket& out);

/// CRC-32 (IEEE 802.3, reflected, init and final xor 0xFFFFFFFF).
uint32_t crc32(const uint8_t* data, size_t size);

/// True when `a` is newer than `b` in 32-bit serial-number arithmetic (RFC 1982).
inline bool newer(uint32_t a, uint32_t b) {
    return a != b && uint32_t(a - b) < 0x80000000u;
}

} // namespace viscera::haptics
