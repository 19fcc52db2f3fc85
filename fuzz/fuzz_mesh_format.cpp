// The studio's mesh format pre-checks (studio/bake/format_check.*): the content sniffing against
// the extension and the structural checks of OBJ, STL (ASCII and binary), PLY (ASCII and binary)
// and GLB that run on an artist's file before assimp sees it. The first byte picks the extension
// (.obj .stl .ply .glb .gltf .fbx, its value mod 6); the rest is the file. Then the check of its
// references to other files (bake/references.*) against a folder that does not exist, so that
// no material library is read.
#include "bake/format_check.hpp"
#include "bake/references.hpp"
#include "sim/util/error.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size == 0) return 0;
    static constexpr std::array<std::string_view, 6> kExtensions{".obj", ".stl", ".ply", ".glb", ".gltf", ".fbx"};
    const std::string_view extension = kExtensions[data[0] % kExtensions.size()];
    const std::string_view bytes(reinterpret_cast<const char*>(data) + 1, size - 1);
    try {
        const auto format = viscera::bake::detail::sniffFormat("mesh", extension, bytes);
        viscera::bake::detail::checkStructure("mesh", format, bytes);
        viscera::bake::detail::checkReferences("mesh", format, bytes, "/nonexistent-viscera-fuzz");
    } catch (const viscera::InputError&) {
    }
    return 0;
}
