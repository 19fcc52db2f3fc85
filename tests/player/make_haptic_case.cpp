// Writes the haptic sample case: make_haptic_case <out.vcase> [tools: 1 or 2] [signing-key.pem].
#include "player/haptic_case.hpp"

#include <cstdio>
#include <exception>
#include <string>

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fputs("usage: make_haptic_case <out.vcase> [1|2] [signing-key.pem]\n", stderr);
        return 2;
    }
    try {
        viscera::test::writeHapticCase(argv[1], argc > 2 ? std::stoi(argv[2]) : 1, argc > 3 ? argv[3] : "");
    } catch (const std::exception& e) {
        std::fprintf(stderr, "make_haptic_case: %s\n", e.what());
        return 1;
    }
    std::printf("%s\n", argv[1]);
    return 0;
}
