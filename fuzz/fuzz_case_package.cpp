// The case package reader and verifier on arbitrary bytes: open (zip, manifest, sizes, SHA-256),
// then read every listed file as the player would.
#include "case/case_package.hpp"
#include "sim/util/error.hpp"

#include <cstddef>
#include <cstdint>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    try {
        auto pkg = viscera::vcase::CasePackage::fromBytes(std::string_view(reinterpret_cast<const char*>(data), size),
                                                          "fuzz.vcase");
        for (const auto& f : pkg->manifest().files)
            (void)pkg->read(f.path);
    } catch (const viscera::InputError&) {
    }
    return 0;
}
