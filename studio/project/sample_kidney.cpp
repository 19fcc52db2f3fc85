#include "project/sample_kidney.hpp"

#include "project/sample_atlas.hpp"

#include "bake/sample_anatomy.hpp"
#include "bake/texture.hpp"
#include "bake/uv_transfer.hpp"
#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"

#include <algorithm>
#include <cmath>
#include <system_error>

namespace viscera::studio {
namespace {

/// The atlas the parts' UVs point into (bake::kidneyAnatomy): the cortex left, the pelvis's two
/// islands upper right, the ureter and artery lower right.
bake::Rgb8Image kidneyAtlas(int size) {
    const AtlasRegion regions[] = {{0.02, 0.02, 0.58, 0.98, {120, 38, 32}},   // cortex: dark red-brown
                                   {0.62, 0.52, 0.79, 0.98, {214, 186, 140}}, // pelvis front: fat-yellow
                                   {0.81, 0.52, 0.98, 0.98, {200, 170, 128}}, // pelvis back
                                   {0.62, 0.02, 0.79, 0.48, {222, 200, 170}}, // ureter: pale
                                   {0.81, 0.02, 0.98, 0.48, {170, 30, 36}}};  // artery and caps: red
    return sampleAtlas(size, regions);
}

} // namespace

Project writeKidneySample(const std::filesystem::path& dir) {
    std::error_code ec;
    std::filesystem::create_directories(dir / "anatomy", ec);
    if (ec) throw InputError(dir.string() + ": cannot make the folder: " + ec.message());
    Project p = newProject(dir, "kidney");
    p.title = "Kidney made from render anatomy";
    p.scene.instructions = "A kidney made simulation-ready from overlapping render parts, textured through its "
                           "transferred UVs, hangs from its hilum and settles under gravity.";
    BodyProject& body = p.bodies.emplace_back();
    body.scene.name = "kidney";
    body.scene.material = newBodyMaterial();
    body.scene.material.youngsModulus = 4000;
    body.mesh.kind = MeshSource::Kind::Remesh;
    RemeshSource& r = body.mesh.remesh;
    for (const bake::RemeshPart& part : bake::kidneyAnatomy()) {
        const std::filesystem::path file = dir / "anatomy" / (part.name + ".obj");
        bake::writeObjWithUv(file.string(), part.surface, part.uv);
        r.parts.push_back({file, bake::CsgOp::Union});
    }
    r.params.voxelCount = 64;
    r.texture = dir / "anatomy" / "kidney.png";
    writeFileAtomic(r.texture, bake::encodePng(kidneyAtlas(1024)));
    body.mesh.meshing.facetSize = 0.006;
    body.mesh.meshing.facetDistance = 0.001;
    body.mesh.meshing.cellSize = 0.008;
    body.mesh.meshing.seed = 7;
    // Held at the hilum, where the artery and ureter leave it.
    body.fixedBoxes = {std::array<sim::Vec3, 2>{sim::Vec3(0.014, -0.012, -0.012), sim::Vec3(0.034, 0.014, 0.014)}};
    p.scene.xpbd.substeps = 40;
    p.scene.xpbd.inertiaScaling = 10; // the few small tets the remeshed hilum leaves get extra inertia
    saveProject(p, dir);
    return loadProject(dir);
}

} // namespace viscera::studio
