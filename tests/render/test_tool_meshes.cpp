// The instruments, probes, clips, needle and thread the renderer draws with the tissue
// (render/tool_meshes.hpp): one mesh each, fixed topology, poses from the snapshot.
#include "render/tool_meshes.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace viscera::render;
using Eigen::Vector3d;

namespace {

ToolPoses snapshot(double jaw, bool energized, bool clipFired) {
    ToolPoses p;
    ToolPoses::Instrument g;
    g.name = "grasper";
    g.kind = "grasper";
    g.tip = Vector3d(-0.03, 0, 0.002);
    g.jaw = jaw;
    g.radius = 0.0015;
    p.instruments.push_back(g);
    ToolPoses::Instrument h = g;
    h.name = "hook";
    h.kind = "energy_hook";
    h.tip = Vector3d(0.01, 0, 0.001);
    h.act = energized;
    p.instruments.push_back(h);
    ToolPoses::Instrument c = g;
    c.name = "clipper";
    c.kind = "clip_applier";
    p.instruments.push_back(c);
    p.maxClips = 1;
    if (clipFired)
        p.clips.push_back(
            {Vector3d(0, -0.002, 0), Vector3d(0, -0.002, 0.004), Vector3d(0, 0.002, 0), Vector3d(0, 0.002, 0.004)});
    p.probes.push_back({Vector3d(0, 0, 0.02), 0.004});
    for (int k = 0; k <= 12; ++k) {
        const double a = M_PI * k / 12;
        p.needle.push_back(Vector3d(0.004 * std::cos(a), 0.004 * std::sin(a), 0.01));
    }
    p.thread = {Vector3d(0.02, 0, 0.01), Vector3d(0.01, 0, 0.01), p.needle.front()};
    return p;
}

double maxDistance(const RenderMesh& m, const std::vector<float>& before) {
    double d = 0;
    for (size_t i = 0; i + 2 < before.size(); i += 3)
        d = std::max(d, double(std::hypot(m.positions[i] - before[i], m.positions[i + 1] - before[i + 1],
                                          m.positions[i + 2] - before[i + 2])));
    return d;
}

} // namespace

TEST(ToolMeshes, OneMeshPerToolWithFixedTopologyAndPosesFromTheSnapshot) {
    SceneView view;
    const ToolMeshes tools(view, snapshot(1.0, false, false));
    // 3 instruments, 1 probe, 1 clip, needle, thread.
    ASSERT_EQ(tools.meshCount(), 7u);
    ASSERT_EQ(view.meshes().size(), 7u);
    for (const RenderMesh& m : view.meshes()) {
        EXPECT_GT(m.triangleCount(), 0u) << m.name;
        EXPECT_EQ(m.normals.size(), m.positions.size()) << m.name;
        EXPECT_EQ(m.heat.size(), m.vertexCount()) << m.name;
        for (float v : m.positions)
            ASSERT_TRUE(std::isfinite(v)) << m.name;
        for (uint32_t i : m.indices)
            ASSERT_LT(i, m.vertexCount()) << m.name;
        EXPECT_LT(view.materials().at(m.material).sssWeight, 1e-6f) << m.name;
    }
    EXPECT_FALSE(view.meshes()[4].visible) << "a clip not yet fired is hidden";
    EXPECT_TRUE(view.meshes()[6].visible) << "the thread";
    // Closed, the grasper's jaws meet at the snapshot's tip: some vertex within a jaw's width of it.
    SceneView closedView;
    const ToolMeshes closed(closedView, snapshot(0.0, false, false));
    double nearest = 1e9;
    const RenderMesh& grasper = closedView.meshes()[0];
    for (size_t v = 0; v < grasper.vertexCount(); ++v)
        nearest = std::min(
            nearest, (Vector3d(grasper.positions[3 * v], grasper.positions[3 * v + 1], grasper.positions[3 * v + 2]) -
                      Vector3d(-0.03, 0, 0.002))
                         .norm());
    EXPECT_LT(nearest, 0.004);
}

TEST(ToolMeshes, JawsCloseTheHookGlowsAndAFiredClipAppears) {
    SceneView view;
    ToolMeshes tools(view, snapshot(1.0, false, false));
    std::vector<std::vector<float>> before;
    std::vector<size_t> counts;
    for (const RenderMesh& m : view.meshes()) {
        before.push_back(m.positions);
        counts.push_back(m.positions.size());
    }
    const uint32_t steel = view.meshes()[1].material;
    tools.update(view, snapshot(0.0, true, true));
    for (size_t i = 0; i < view.meshes().size(); ++i)
        EXPECT_EQ(view.meshes()[i].positions.size(), counts[i]) << "topology is fixed: " << view.meshes()[i].name;
    EXPECT_GT(maxDistance(view.meshes()[0], before[0]), 1e-3) << "the grasper's jaws closed";
    EXPECT_LT(maxDistance(view.meshes()[3], before[3]), 1e-9) << "the probe did not move";
    EXPECT_NE(view.meshes()[1].material, steel) << "an energized hook is drawn hot";
    EXPECT_TRUE(view.meshes()[4].visible) << "the fired clip";
    // A non-finite pose changes nothing; the hook cools when the energy goes off.
    ToolPoses bad = snapshot(0.5, false, true);
    bad.instruments[0].tip = Vector3d(NAN, 0, 0);
    const std::vector<float> held = view.meshes()[0].positions;
    tools.update(view, bad);
    EXPECT_EQ(view.meshes()[0].positions, held);
    EXPECT_EQ(view.meshes()[1].material, steel);
    // A thread shorter than 0.1 mm is hidden.
    ToolPoses shortThread = snapshot(0.5, false, true);
    shortThread.thread = {shortThread.needle.front(), shortThread.needle.front() + Vector3d(1e-5, 0, 0)};
    tools.update(view, shortThread);
    EXPECT_FALSE(view.meshes()[6].visible);
}

TEST(ToolMeshes, AnEmptySnapshotAddsNothing) {
    SceneView view;
    const ToolMeshes tools(view, ToolPoses{});
    EXPECT_EQ(tools.meshCount(), 0u);
    EXPECT_TRUE(view.meshes().empty());
    EXPECT_TRUE(view.materials().empty());
}

TEST(ToolMeshes, TheNeedleHolderGripsTheNeedleAwayFromItsCentre) {
    // A semicircular needle of radius 8 mm around the origin in the z = 0 plane, end to tip.
    std::vector<Vector3d> needle;
    for (int k = 0; k <= 24; ++k) {
        const double a = M_PI * k / 24.0;
        needle.push_back(Vector3d(0.008 * std::cos(a), 0.008 * std::sin(a), 0.0));
    }
    const ToolPoses::Instrument h = needleHolderPose(needle);
    EXPECT_EQ(h.kind, "needle_holder");
    EXPECT_EQ(h.jaw, 0.0) << "closed on the needle";
    EXPECT_NEAR(h.tip.norm(), 0.008, 1e-12) << "the jaws are on the needle";
    EXPECT_NEAR(h.direction.norm(), 1.0, 1e-12);
    const Vector3d shaft = -h.direction; // from the tip up the shaft
    EXPECT_GT(shaft.dot(h.tip.normalized()), 0.5) << "away from the arc's centre";
    EXPECT_GT(std::abs(shaft.z()), 0.5) << "out of the needle's plane";
    const Vector3d tangent = (needle[9] - needle[7]).normalized();
    EXPECT_LT(std::abs(shaft.dot(tangent)), 0.1) << "across the needle, not along it";
    // Degenerate input: a pose, no NaN.
    const ToolPoses::Instrument d = needleHolderPose({Vector3d::Zero(), Vector3d::Zero()});
    EXPECT_TRUE(d.direction.allFinite());
    EXPECT_TRUE(needleHolderPose({}).tip.allFinite());
}
