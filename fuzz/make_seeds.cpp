// Writes seed packets for fuzz_console_protocol into the given folder: a state packet and a command
// packet as the console and the player send them (two arms, pedals, a force), so that the fuzzer
// starts past the header and checksum.
#include "haptics/console_protocol.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: make_seeds <dir>\n");
        return 2;
    }
    const std::filesystem::path dir = argv[1];
    std::filesystem::create_directories(dir);
    uint8_t buf[2048];
    viscera::haptics::StatePacket s;
    s.sequence = 7;
    s.timestamp_ns = 123456789;
    s.arms = 2;
    s.pedals = 0x5;
    const size_t ns = viscera::haptics::encode(s, buf, sizeof buf);
    std::ofstream(dir / "state.bin", std::ios::binary).write(reinterpret_cast<const char*>(buf), long(ns));
    viscera::haptics::CommandPacket c;
    c.sequence = 9;
    c.echoSequence = 7;
    const size_t nc = viscera::haptics::encode(c, buf, sizeof buf);
    std::ofstream(dir / "command.bin", std::ios::binary).write(reinterpret_cast<const char*>(buf), long(nc));
    std::printf("make_seeds: %zu + %zu bytes in %s\n", ns, nc, dir.c_str());
    return ns && nc ? 0 : 1;
}
