// Writes the haptic sample case: make_haptic_case <out.vcase> [tools: 1 or 2].
#include "player/haptic_case.hpp"

#include <cstdio>
#include <exception>
#include <string>

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fputs("usage: make_haptic_case <out.vcase> [1|2]\n", stderr);
        return 2;
    }
    try {
        viscera::test::writeHapticCase(argv[1], argc > 2 ? std::stoi(argv[2]) : 1);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "make_haptic_case: %s\n", e.what());
        return 1;
    }
    std::printf("%s\n", argv[1]);
    return 0;
}
