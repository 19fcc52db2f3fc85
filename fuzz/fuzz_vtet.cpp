// .vtet (tet meshes) and .vtri (surfaces); the first byte picks the reader.
#include "sim/mesh/tet_io.hpp"
#include "sim/util/error.hpp"

#include <cstddef>
#include <cstdint>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size == 0) return 0;
    const std::string_view text(reinterpret_cast<const char*>(data) + 1, size - 1);
    try {
        if (data[0] & 1)
            (void)viscera::sim::parseVtri(text, "mesh.vtri");
        else
            (void)viscera::sim::parseVtet(text, "mesh.vtet");
    } catch (const viscera::InputError&) {
    }
    return 0;
}
