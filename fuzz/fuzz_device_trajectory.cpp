// A device replay trajectory (--device replay:<file.csv>, viscera-console-sim --trajectory).
#include "haptics/trajectory.hpp"
#include "sim/util/error.hpp"

#include <cstddef>
#include <cstdint>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    try {
        (void)viscera::haptics::Trajectory::parse(std::string_view(reinterpret_cast<const char*>(data), size),
                                                  "replay.csv");
    } catch (const viscera::InputError&) {
    }
    return 0;
}
