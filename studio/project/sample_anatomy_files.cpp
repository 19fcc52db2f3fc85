#include "project/sample_anatomy_files.hpp"

#include "bake/sample_anatomy.hpp"
#include "bake/uv_transfer.hpp"
#include "project/sample_atlas.hpp"
#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"

#include <system_error>

namespace viscera::studio {

namespace {

AnatomyFiles writeParts(const std::filesystem::path& dir, const std::vector<bake::RemeshPart>& parts) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) throw InputError(dir.string() + ": cannot make the folder: " + ec.message());
    requireWritableFolder(dir);
    AnatomyFiles out;
    for (const bake::RemeshPart& part : parts) {
        out.parts.push_back(dir / (part.name + ".obj"));
        bake::writeObjWithUv(out.parts.back().string(), part.surface, part.uv);
    }
    return out;
}

} // namespace

AnatomyFiles writeRectumAnatomy(const std::filesystem::path& dir) {
    return writeParts(dir, bake::rectumAnatomy());
}

AnatomyFiles writeHepatocysticAnatomy(const std::filesystem::path& dir) {
    AnatomyFiles out = writeParts(dir, bake::hepatocysticAnatomy());
    // The islands of bake::hepatocysticAnatomy's UVs, in tissue colours.
    const AtlasRegion regions[] = {{0.02, 0.02, 0.58, 0.98, {112, 42, 34}},   // liver: red-brown
                                   {0.62, 0.52, 0.79, 0.98, {92, 118, 70}},   // gallbladder: green
                                   {0.81, 0.52, 0.98, 0.98, {84, 110, 64}},   //   its other half
                                   {0.62, 0.27, 0.79, 0.48, {206, 200, 150}}, // cystic duct: pale
                                   {0.62, 0.02, 0.79, 0.23, {196, 190, 140}}, // common bile duct
                                   {0.81, 0.02, 0.98, 0.48, {170, 30, 36}}};  // cystic artery: red
    out.atlas = dir / "hepatocystic.png";
    writeFileAtomic(out.atlas, bake::encodePng(sampleAtlas(1024, regions)));
    return out;
}

} // namespace viscera::studio
