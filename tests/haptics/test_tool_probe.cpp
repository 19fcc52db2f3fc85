// Sphere probes against a tissue block: the probe pushes nodes out, the contact force grows with
// the depth and points out of the tissue, no contact gives the gap; only "probe" scenes get them.
#include "sim/mesh/generators.hpp"
#include "sim/scene/world.hpp"

#include "sim/util/error.hpp"

#include <gtest/gtest.h>

using namespace viscera::sim;

namespace {

std::unique_ptr<World> block(double probeZ, std::vector<std::string> features = {"probe", "xpbd"}) {
    BoxSpec box{Vec3::Zero(), Vec3(0.04, 0.04, 0.02), {4, 4, 2}};
    auto mesh = makeBoxTetMesh(box);
    SceneDesc scene;
    scene.xpbd.substeps = 25;
    scene.xpbd.gravity = Vec3::Zero();
    scene.xpbd.threads = 1;
    BodyDesc body;
    body.name = "tissue";
    body.meshPath = "m.vtet";
    body.material.youngsModulus = 5000;
    for (int32_t v = 0; v < static_cast<int32_t>(mesh->vertexCount()); ++v)
        if (mesh->positions()[v].z() < 1e-9) body.fixedNodes.push_back(v);
    scene.bodies.push_back(body);
    ToolDesc probe;
    probe.name = "probe";
    probe.radius = 0.006;
    probe.start = Vec3(0.02, 0.02, probeZ);
    scene.tools.push_back(probe);
    std::vector<std::unique_ptr<TetMesh>> meshes;
    meshes.push_back(std::move(mesh));
    return World::assemble(scene, std::move(meshes), {}, features, "test");
}

} // namespace

TEST(ToolProbe, NoContactReportsTheGap) {
    auto w = block(0.03);
    ASSERT_EQ(w->toolCount(), 1u);
    w->step();
    const ToolContact& c = w->toolContact(0);
    EXPECT_EQ(c.nodes, 0);
    EXPECT_EQ(c.force.norm(), 0.0);
    EXPECT_NEAR(c.gap, 0.03 - 0.006 - 0.02, 1e-6);
    EXPECT_GT(c.normal.z(), 0.99);
    EXPECT_GT(c.stiffness, 0.0);
}

TEST(ToolProbe, PressingHarderGivesMoreForceOutOfTheTissue) {
    double previous = 0;
    for (double depth : {0.001, 0.002, 0.003}) { // up to half the radius
        auto w = block(0.02 + 0.006 - depth);
        for (int f = 0; f < 5; ++f)
            w->step();
        const ToolContact& c = w->toolContact(0);
        EXPECT_GT(c.nodes, 0) << depth;
        EXPECT_GT(c.force.z(), previous) << depth;
        EXPECT_GT(c.normal.z(), 0.9) << "pushes the probe up, out of the tissue";
        EXPECT_TRUE(w->invariants().allFinite);
        // Every free node ends outside the probe.
        for (const Vec3& x : w->positions(0))
            EXPECT_GE((x - c.centre).norm(), 0.006 - 1e-9);
        previous = c.force.z();
    }
}

TEST(ToolProbe, MovesAreCutToOneRadiusPerFrameAndNonFiniteIgnored) {
    auto w = block(0.03);
    w->setToolPosition(0, Vec3(0.02, 0.02, 0.10));
    w->step();
    EXPECT_NEAR(w->toolContact(0).centre.z(), 0.036, 1e-12);
    w->setToolPosition(0, Vec3(NAN, 0, 0));
    w->step();
    EXPECT_NEAR(w->toolContact(0).centre.z(), 0.036, 1e-12);
}

TEST(ToolProbe, ToolsNeedTheProbeFeatureAndParseStrictly) {
    EXPECT_THROW(block(0.03, {"xpbd"}), viscera::InputError);
    const std::string base = R"({"solver": {"type": "xpbd"}, "bodies": [{"name": "b", "mesh": "m.vtet",
        "material": {"model": "stable_neo_hookean", "youngs_modulus": 1e4, "poisson_ratio": 0.4, "density": 1000}}],
        "tools": )";
    EXPECT_NO_THROW(parseScene(base + R"([{"name": "p", "start": [0, 0, 0.1], "hand": "left"}]})", "s.json"));
    for (const char* bad : {R"([{"name": "p"}])", R"([{"name": "p", "start": [0, 0, 0], "radius": -1}])",
                            R"([{"name": "p", "start": [0, 0, 0], "hand": "middle"}])",
                            R"([{"name": "p", "start": [0, 0, 0], "shape": "cube"}])"})
        EXPECT_THROW(parseScene(base + bad + "}", "s.json"), viscera::InputError) << bad;
    SceneDesc s = parseScene(base + R"([{"name": "p", "start": [0, 0, 0.1], "radius": 0.004}]})", "s.json");
    const SceneDesc again = parseScene(formatScene(s), "again");
    ASSERT_EQ(again.tools.size(), 1u);
    EXPECT_DOUBLE_EQ(again.tools[0].radius, 0.004);
    EXPECT_EQ(requiredFeatures(again), std::vector<std::string>({"probe", "xpbd"}));
}
