// An instrument track (tools/*.track of a case).
#include "sim/scene/instrument_track.hpp"
#include "sim/util/error.hpp"

#include <cstddef>
#include <cstdint>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    try {
        (void)viscera::sim::InstrumentTrack::parse(std::string_view(reinterpret_cast<const char*>(data), size),
                                                   "tools/hook.track");
    } catch (const viscera::InputError&) {
    }
    return 0;
}
