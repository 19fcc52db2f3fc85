// The console protocol decoder: a UDP datagram as a state packet and as a command packet
// (never throws: a decode error is its answer).
#include "haptics/console_protocol.hpp"
#include "sim/util/error.hpp"

#include <cstddef>
#include <cstdint>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    viscera::haptics::StatePacket s;
    viscera::haptics::CommandPacket c;
    (void)viscera::haptics::decode(data, size, s);
    (void)viscera::haptics::decode(data, size, c);
    return 0;
}
