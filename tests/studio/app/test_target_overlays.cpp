// What the target tool draws [issue 57 item 2]: the cut lines with rings of their radius, the clip
// sites inside spheres of their tolerance, the suture plane's square; non-finite or degenerate
// targets draw nothing instead of NaN vertices.
#include "app/target_overlays.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace {

using namespace viscera;
using sim::Vec3;

bool finite(const render::RenderMesh& m) {
    for (float v : m.positions)
        if (!std::isfinite(v)) return false;
    return true;
}

/// Largest distance of a vertex from `c` (m).
double reach(const render::RenderMesh& m, const Vec3& c) {
    double r = 0;
    for (size_t k = 0; k + 2 < m.positions.size(); k += 3)
        r = std::max(r, (Vec3(m.positions[k], m.positions[k + 1], m.positions[k + 2]) - c).norm());
    return r;
}

TEST(TargetOverlays, ACutLineIsDrawnWithRingsOfItsRadiusOnTopOfTheSurface) {
    sim::CutTarget cut;
    cut.line = {Vec3(0, 0, 0), Vec3(0.02, 0, 0), Vec3(0.04, 0, 0)};
    cut.radius = 0.004;
    const render::RenderMesh m = studio::cutTargetsMesh({cut}, 0);
    EXPECT_EQ(m.name, "cut targets");
    EXPECT_TRUE(m.drawOnTop);
    ASSERT_GT(m.vertexCount(), 0u);
    EXPECT_TRUE(finite(m));
    // the rings lie in planes across the line, radius 4 mm (+ the tube's own radius)
    double maxOff = 0;
    for (size_t k = 0; k + 2 < m.positions.size(); k += 3)
        maxOff = std::max(maxOff, std::hypot(double(m.positions[k + 1]), double(m.positions[k + 2])));
    EXPECT_NEAR(maxOff, 0.004, 1e-3);
    // a line of NaN points or one point draws nothing
    sim::CutTarget bad = cut;
    bad.line[1] = Vec3(NAN, 0, 0);
    EXPECT_EQ(studio::cutTargetsMesh({bad}, 0).vertexCount(), 0u);
    bad.line = {Vec3::Zero()};
    EXPECT_EQ(studio::cutTargetsMesh({bad}, 0).vertexCount(), 0u);
}

TEST(TargetOverlays, AClipSiteIsACrossInsideASphereOfItsTolerance) {
    sim::ClipTarget clip;
    clip.position = Vec3(0.01, 0.02, 0.03);
    clip.tolerance = 0.006;
    const render::RenderMesh m = studio::clipTargetsMesh({clip}, 0);
    EXPECT_EQ(m.name, "clip targets");
    ASSERT_GT(m.vertexCount(), 0u);
    EXPECT_NEAR(reach(m, clip.position), 0.006, 1e-3);
    clip.position.x() = INFINITY;
    EXPECT_EQ(studio::clipTargetsMesh({clip}, 0).vertexCount(), 0u);
}

TEST(TargetOverlays, TheSuturePlaneIsASquareAcrossItsNormal) {
    sim::SutureTarget s;
    s.planePoint = Vec3(0, 0, 0.01);
    s.planeNormal = Vec3(0, 0, 1);
    const render::RenderMesh m = studio::sutureTargetMesh(s, 0.03, 0);
    ASSERT_GT(m.vertexCount(), 0u);
    EXPECT_TRUE(finite(m));
    EXPECT_NEAR(reach(m, s.planePoint), 0.015 * std::sqrt(2.0), 1e-3); // the square's corners
    EXPECT_EQ(studio::sutureTargetMesh(s, 0, 0).vertexCount(), 0u) << "size 0: nothing";
    s.planeNormal = Vec3::Zero();
    EXPECT_EQ(studio::sutureTargetMesh(s, 0.03, 0).vertexCount(), 0u);
}

TEST(TargetOverlays, WhatIsBeingPickedIsDrawnUntilTaken) {
    EXPECT_EQ(studio::pendingTargetMesh({}, std::nullopt, 0).vertexCount(), 0u);
    EXPECT_GT(studio::pendingTargetMesh({Vec3::Zero(), Vec3(0.01, 0, 0)}, std::nullopt, 0).vertexCount(), 0u);
    EXPECT_GT(studio::pendingTargetMesh({}, Vec3::Zero(), 0).vertexCount(), 0u);
    EXPECT_EQ(studio::pendingTargetMesh({}, Vec3(NAN, 0, 0), 0).vertexCount(), 0u);
}

} // namespace
