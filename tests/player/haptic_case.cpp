// The haptic sample case (a slab with one or two sphere probes), written by code: shared by the
// player e2e tests and the make_haptic_case tool. Not a test itself.
#include "player/haptic_case.hpp"

#include "case/case_writer.hpp"
#include "sim/mesh/generators.hpp"
#include "sim/mesh/tet_io.hpp"
#include "sim/scene/world.hpp"

#include <optional>

namespace viscera::test {
namespace {
sim::BoxSpec box() {
    return {sim::Vec3::Zero(), sim::Vec3(0.06, 0.04, 0.02), {8, 6, 3}};
}
} // namespace

sim::SceneDesc hapticScene(int tools) {
    auto mesh = sim::makeBoxTetMesh(box());
    sim::SceneDesc scene;
    scene.instructions = "Press the tissue gently with the probe, hold, and release. Keep the force below 4 N.";
    scene.xpbd.gravity = sim::Vec3(0, 0, -9.81);
    scene.xpbd.substeps = 45;
    scene.xpbd.threads = 1;
    scene.xpbd.damping = 2.0;
    sim::BodyDesc body;
    body.name = "tissue";
    body.meshPath = "meshes/tissue.vtet";
    body.material.youngsModulus = 20000;
    body.material.poissonRatio = 0.4;
    for (int32_t v = 0; v < static_cast<int32_t>(mesh->vertexCount()); ++v)
        if (mesh->positions()[v].z() < 1e-9) body.fixedNodes.push_back(v);
    scene.bodies.push_back(body);
    for (int t = 0; t < tools; ++t) {
        sim::ToolDesc probe;
        probe.name = tools == 1 ? "probe" : (t == 0 ? "probe-left" : "probe-right");
        probe.hand = tools == 1 ? "right" : (t == 0 ? "left" : "right");
        probe.radius = 0.005;
        // Over a column of nodes (spacing 7.5 × 6.7 mm): node-based contact lets a probe slip between them.
        probe.start = sim::Vec3(tools == 1 ? 0.03 : 0.015 + 0.03 * t, 0.02, 0.028);
        probe.motionScale = 0.15;
        scene.tools.push_back(probe);
    }
    return scene;
}

void writeHapticCase(const std::filesystem::path& out, int tools, const std::filesystem::path& signingKey) {
    const sim::SceneDesc scene = hapticScene(tools);
    auto mesh = sim::makeBoxTetMesh(box());
    vcase::Manifest header;
    header.caseId = tools == 1 ? "haptic-slab" : "haptic-slab-bimanual";
    header.caseVersion = "1.0.0";
    header.minPlayerVersion = "0.1.0";
    header.title = tools == 1 ? "Press the tissue" : "Bimanual press";
    header.features = sim::requiredFeatures(scene);
    vcase::CaseWriter w(header);
    w.addFile("scene.json", sim::formatScene(scene));
    w.addFile("meshes/tissue.vtet", sim::formatVtet(*mesh));
    std::optional<vcase::SigningKey> key;
    if (!signingKey.empty()) {
        key = vcase::SigningKey::load(signingKey);
        w.sign(*key, "Viscera tests");
    }
    w.write(out);
}

} // namespace viscera::test
