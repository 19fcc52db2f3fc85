// The recorded needle trajectory of a suturing case (suture.trajectory).
#include "sim/suture/anastomosis.hpp"
#include "sim/util/error.hpp"

#include <cstddef>
#include <cstdint>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    try {
        (void)viscera::sim::parseTrajectory(std::string_view(reinterpret_cast<const char*>(data), size), "needle.csv");
    } catch (const viscera::InputError&) {
    }
    return 0;
}
