// manifest.json of a case package.
#include "case/manifest.hpp"
#include "sim/util/error.hpp"

#include <cstddef>
#include <cstdint>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    try {
        (void)viscera::vcase::Manifest::parse(std::string_view(reinterpret_cast<const char*>(data), size),
                                              "manifest.json");
    } catch (const viscera::InputError&) {
    }
    return 0;
}
