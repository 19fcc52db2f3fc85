// .vweights (painted node weights); the first two bytes give the mesh's node count.
#include "sim/skeleton/node_weights_io.hpp"
#include "sim/util/error.hpp"

#include <cstddef>
#include <cstdint>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size < 2) return 0;
    const size_t nodes = size_t(data[0]) | size_t(data[1]) << 8;
    try {
        (void)viscera::sim::parseNodeWeights(std::string_view(reinterpret_cast<const char*>(data) + 2, size - 2),
                                             "body.vweights", nodes);
    } catch (const viscera::InputError&) {
    }
    return 0;
}
