// The stiffness paint tool's authoring meshes (no display needed): the section of a tet mesh by a
// plane (its area, its vertices on the plane, weights interpolated exactly for a linear field),
// the cut-away mask, the skeleton tubes and the weight ramp.
#include "app/paint_overlays.hpp"
#include "sim/mesh/generators.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace viscera;

namespace {

double sectionArea(const render::RenderMesh& m) {
    double a = 0;
    for (size_t f = 0; f + 2 < m.indices.size(); f += 3) {
        auto p = [&](uint32_t i) {
            return Eigen::Vector3d(m.positions[3 * i], m.positions[3 * i + 1], m.positions[3 * i + 2]);
        };
        a += 0.5 * (p(m.indices[f + 1]) - p(m.indices[f])).cross(p(m.indices[f + 2]) - p(m.indices[f])).norm();
    }
    return a;
}

} // namespace

TEST(PaintOverlays, SectionOfABoxIsItsCrossSectionWithExactlyInterpolatedWeights) {
    const auto mesh = sim::makeBoxTetMesh({sim::Vec3(0, 0, 0), sim::Vec3(0.1, 0.02, 0.04), {10, 4, 4}});
    std::vector<double> w(mesh->vertexCount());
    for (size_t i = 0; i < w.size(); ++i)
        w[i] = 1.0 + 50.0 * mesh->positions()[i].y(); // linear: 1 .. 2 across y
    for (double at : {0.0137, 0.05, 0.0899}) {
        SCOPED_TRACE(at);
        const studio::CutPlane plane{Eigen::Vector3d::UnitX(), at};
        const render::RenderMesh s = studio::sliceMesh(*mesh, w, 1.0, plane, 0);
        ASSERT_GT(s.triangleCount(), 0u);
        EXPECT_NEAR(sectionArea(s), 0.02 * 0.04, 1e-9) << "the whole cross-section, once";
        ASSERT_EQ(s.overlay.size(), 4 * s.vertexCount());
        for (size_t v = 0; v < s.vertexCount(); ++v) {
            EXPECT_NEAR(s.positions[3 * v], at, 1e-6) << "on the plane";
            const Eigen::Vector4f expected = studio::weightColour(1.0 + 50.0 * s.positions[3 * v + 1], 1.0);
            for (int c = 0; c < 3; ++c)
                EXPECT_NEAR(s.overlay[4 * v + c], expected[c], 2e-5) << "vertex " << v;
            EXPECT_EQ(s.overlay[4 * v + 3], 1.0f);
        }
    }
    // a plane outside the mesh cuts nothing
    EXPECT_EQ(studio::sliceMesh(*mesh, w, 1.0, {Eigen::Vector3d::UnitX(), 0.2}, 0).triangleCount(), 0u);
}

TEST(PaintOverlays, CutAwayHidesTheFacesOnTheCutSide) {
    render::RenderMesh m;
    m.indices = {0, 1, 2, 3, 4, 5};
    m.rest = {0, 0, 0, 0.01f, 0, 0, 0, 0.01f, 0, 1, 0, 0, 1.01f, 0, 0, 1, 0.01f, 0};
    m.positions = m.rest;
    const auto mask = studio::cutAwayMask(m, {Eigen::Vector3d::UnitX(), 0.5});
    ASSERT_EQ(mask.size(), 2u);
    EXPECT_EQ(mask[0], 1);
    EXPECT_EQ(mask[1], 0);
}

TEST(PaintOverlays, SkeletonTubesAndRamp) {
    sim::Skeleton sk;
    sk.nodes = {sim::Vec3(0, 0, 0), sim::Vec3(0.05, 0, 0), sim::Vec3(0.05, 0.03, 0)};
    sk.edges = {{0, 1}, {1, 2}};
    const render::RenderMesh t = studio::skeletonMesh(sk, 0.001f, 0);
    EXPECT_EQ(t.triangleCount(), 2u * 12u);
    for (size_t v = 0; v < t.vertexCount(); ++v) {
        // every tube vertex lies at the radius from its edge's axis
        const Eigen::Vector3d p(t.positions[3 * v], t.positions[3 * v + 1], t.positions[3 * v + 2]);
        const sim::Vec3& a = sk.nodes[sk.edges[v / 12][0]];
        const sim::Vec3 d = (sk.nodes[sk.edges[v / 12][1]] - a).normalized();
        EXPECT_NEAR(((p - a) - (p - a).dot(d) * d).norm(), 0.001, 1e-6);
    }
    EXPECT_TRUE(studio::skeletonMesh({}, 0.001f, 0).indices.empty());
    // ramp: base grey and faint, 4x red, 1/4 blue, beyond clamped, non-finite as base colour
    EXPECT_FLOAT_EQ(studio::weightColour(1.0, 1.0)[3], 0.35f);
    EXPECT_FLOAT_EQ(studio::weightColour(4.0, 1.0)[0], 0.9f);
    EXPECT_FLOAT_EQ(studio::weightColour(0.25, 1.0)[2], 0.95f);
    EXPECT_EQ(studio::weightColour(100.0, 1.0), studio::weightColour(4.0, 1.0));
    const Eigen::Vector4f nan = studio::weightColour(NAN, 1.0);
    EXPECT_TRUE(nan.allFinite());
}

TEST(PaintOverlays, TheBrushRingLiesOnTheTangentPlaneAtTheBrushRadius) {
    const Eigen::Vector3d c(0.01, -0.02, 0.03), n = Eigen::Vector3d(1, 2, 2).normalized();
    const double radius = 0.012;
    const render::RenderMesh ring = studio::brushRingMesh(c, n, radius, 0);
    EXPECT_EQ(ring.name, "brush");
    ASSERT_EQ(ring.vertexCount(), 96u);
    ASSERT_EQ(ring.triangleCount(), 96u);
    const double band = 0.04 * radius;
    for (size_t v = 0; v < ring.vertexCount(); ++v) {
        const Eigen::Vector3d p(ring.positions[3 * v], ring.positions[3 * v + 1], ring.positions[3 * v + 2]);
        const Eigen::Vector3d d = p - c;
        EXPECT_NEAR(d.dot(n), 0.01 * radius, 1e-7) << "lifted off the surface by 1 % of the radius";
        const double r = (d - d.dot(n) * n).norm();
        EXPECT_NEAR(r, radius, 0.5 * band + 1e-7) << v;
    }
    ASSERT_EQ(ring.overlay.size(), 4 * ring.vertexCount());
    // nothing for a degenerate brush
    EXPECT_EQ(studio::brushRingMesh(c, Eigen::Vector3d::Zero(), radius, 0).vertexCount(), 0u);
    EXPECT_EQ(studio::brushRingMesh(c, n, 0.0, 0).vertexCount(), 0u);
}
