// UV transfer (bake/uv_transfer.hpp) [A §3.3]: on a flat sheet with two islands and on a tube
// whose seam lies inside its one island, closest-point and island-labelled transfers stretch the
// triangles over the seam (Fig. 3.4 cases 1 and 3) and the seam cut leaves none crossing it, with
// UVs exact to rounding where the source map is affine; the kidney sample end to end.
#include "bake/remesh.hpp"
#include "bake/sample_anatomy.hpp"
#include "bake/uv_transfer.hpp"

#include "sim/mesh/generators.hpp"
#include "sim/util/error.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <set>
#include <vector>

using namespace viscera;
using ::testing::HasSubstr;
using Vec2 = Eigen::Vector2d;

namespace {

/// A flat n × n grid over [0, 0.02]² (z = 0), counter-clockwise from +z.
sim::TriMesh grid(int n, double size = 0.02, double z = 0, double skew = 0) {
    std::vector<sim::Vec3> p;
    std::vector<sim::Tri> t;
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) {
            const double x = size * i / n, y = size * j / n;
            // skew shears the interior columns so the target's edges cross x = size/2 obliquely
            const bool inside = i > 0 && i < n;
            p.emplace_back(x + (inside ? skew * size * (double(j) / n - 0.5) / n : 0.0), y, z);
        }
    auto id = [&](int i, int j) { return int32_t(j * (n + 1) + i); };
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            t.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
            t.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
        }
    return sim::TriMesh::fromArrays(std::move(p), std::move(t));
}

/// The source sheet: 8 × 8 triangles, the left half (x < 1 cm) one island mapped to u in
/// [0, 0.4], the right half another mapped to u in [0.6, 1] mirrored: UVs affine in each half.
bake::RemeshPart sheetWithTwoIslands() {
    bake::RemeshPart part{"sheet", grid(8), bake::CsgOp::Union, {}};
    for (const sim::Tri& t : part.surface.triangles()) {
        sim::Vec3 c = sim::Vec3::Zero();
        for (int32_t v : t)
            c += part.surface.positions()[v] / 3.0;
        bake::CornerUv uv;
        for (int k = 0; k < 3; ++k) {
            const sim::Vec3& x = part.surface.positions()[t[k]];
            uv[k] = c.x() < 0.01 ? Vec2(40 * x.x(), 50 * x.y()) : Vec2(1.0 - 40 * (x.x() - 0.01), 50 * x.y());
        }
        part.uv.push_back(uv);
    }
    return part;
}

/// The side of a capped tube along z (its caps' triangles, those touching the axis, dropped).
sim::TriMesh tubeSide(const sim::TriMesh& closed) {
    std::vector<sim::Tri> side;
    for (const sim::Tri& t : closed.triangles()) {
        bool cap = false;
        for (int32_t v : t)
            cap = cap || closed.positions()[v].head<2>().norm() < 1e-9;
        if (!cap) side.push_back(t);
    }
    return sim::TriMesh::fromArrays(closed.positions(), side);
}

/// An open tube of radius 4 mm along z, 2 cm long, side unwrapped into one island: u the angle,
/// v along; the seam at angle ±π lies inside the island.
bake::RemeshPart unwrappedTube(int slices) {
    const sim::Vec3 a(0, 0, 0), b(0, 0, 0.02);
    bake::RemeshPart part{"tube", tubeSide(sim::makeTubeSurface(a, b, 0.004, slices, 8)), bake::CsgOp::Union, {}};
    for (const sim::Tri& t : part.surface.triangles()) {
        std::array<double, 3> phi{};
        for (int k = 0; k < 3; ++k) {
            const sim::Vec3& x = part.surface.positions()[t[k]];
            phi[k] = std::atan2(x.y(), x.x());
        }
        // Unwrap around the first corner, then keep the mean in [−π, π).
        for (int k = 1; k < 3; ++k) {
            if (phi[k] - phi[0] > std::numbers::pi) phi[k] -= 2 * std::numbers::pi;
            if (phi[k] - phi[0] < -std::numbers::pi) phi[k] += 2 * std::numbers::pi;
        }
        const double mean = (phi[0] + phi[1] + phi[2]) / 3;
        const double shift = mean >= std::numbers::pi ? -2 * std::numbers::pi : 0.0;
        bake::CornerUv uv;
        for (int k = 0; k < 3; ++k)
            uv[k] = Vec2((phi[k] + shift + std::numbers::pi) / (2 * std::numbers::pi),
                         part.surface.positions()[t[k]].z() / 0.02);
        part.uv.push_back(uv);
    }
    return part;
}

sim::TriMesh tubeTarget(int slices) {
    return tubeSide(sim::makeTubeSurface({0, 0, 0.001}, {0, 0, 0.019}, 0.004, slices, 7));
}

} // namespace

TEST(bake_uv_transfer, TheSourceKnowsItsIslandsAndSeams) {
    const bake::UvSource sheet({sheetWithTwoIslands()});
    EXPECT_EQ(sheet.islandCount(), 2u);
    EXPECT_EQ(sheet.seamEdgeCount(), 8u); // the column of edges at x = 1 cm
    const bake::UvSource tube({unwrappedTube(24)});
    EXPECT_EQ(tube.islandCount(), 1u);
    EXPECT_EQ(tube.seamEdgeCount(), 8u); // one edge per ring, inside the island
    // Closest point: exact UV on the sheet's affine map.
    const bake::UvSource::Hit h = sheet.closest({0.005, 0.01, 0.001});
    EXPECT_NEAR(h.uv.x(), 0.2, 1e-12);
    EXPECT_NEAR(h.uv.y(), 0.5, 1e-12);
    EXPECT_NEAR(h.distance, 0.001, 1e-12);
}

TEST(bake_uv_transfer, SeamCuttingLeavesNoTriangleOverTwoIslandsAndIsExactOnAnAffineMap) {
    const bake::UvSource source({sheetWithTwoIslands()});
    // Target: a coarser, sheared grid 0.2 mm above: its edges cross the seam obliquely.
    const sim::TriMesh target = grid(5, 0.02, 0.0002, 0.6);
    const auto closestUv = bake::transferUv(source, target, bake::UvTransferMethod::ClosestPoint);
    const auto closest = bake::measureUvTransfer(source, target, closestUv, 4000);
    const auto labelled = bake::measureUvTransfer(
        source, target, bake::transferUv(source, target, bake::UvTransferMethod::IslandLabelled), 4000);
    EXPECT_GT(closest.spanningIslands, 0u);
    EXPECT_GT(closest.seamCrossed, 0u);
    EXPECT_GT(closest.overThreshold, 0.0);
    EXPECT_GT(closest.uvErrorMax, 0.1); // a triangle over the seam interpolates across the atlas
    EXPECT_EQ(labelled.spanningIslands, closest.spanningIslands); // same mesh: the label fixes UVs, not geometry
    // What the label does fix: every UV triangle lies in one island's part of the atlas (u ≤ 0.4
    // or u ≥ 0.6); the closest-point transfer has triangles over the gap between them.
    auto overTheGap = [](const std::vector<bake::CornerUv>& uv) {
        size_t n = 0;
        for (const bake::CornerUv& c : uv) {
            const bool left = c[0].x() <= 0.4 + 1e-9 && c[1].x() <= 0.4 + 1e-9 && c[2].x() <= 0.4 + 1e-9;
            const bool right = c[0].x() >= 0.6 - 1e-9 && c[1].x() >= 0.6 - 1e-9 && c[2].x() >= 0.6 - 1e-9;
            n += left || right ? 0 : 1;
        }
        return n;
    };
    EXPECT_GT(overTheGap(closestUv), 0u);
    EXPECT_EQ(overTheGap(bake::transferUv(source, target, bake::UvTransferMethod::IslandLabelled)), 0u);

    bake::SeamCutReport report;
    const bake::UvMesh cut = bake::cutAlongSeams(source, target, {}, &report);
    EXPECT_GT(report.crossedEdges + report.snappedVertices, 0u);
    EXPECT_GT(report.seamEdges, 0u);
    EXPECT_EQ(report.unresolvedPieces, 0u);
    EXPECT_TRUE(cut.mesh.triangleCount() > target.triangleCount());
    const auto uv = bake::transferUv(source, cut.mesh, bake::UvTransferMethod::SeamCutting);
    const auto seam = bake::measureUvTransfer(source, cut.mesh, uv, 4000);
    EXPECT_EQ(seam.spanningIslands, 0u);
    EXPECT_EQ(seam.seamCrossed, 0u);
    EXPECT_EQ(seam.flipped, 0u);
    EXPECT_EQ(seam.overThreshold, 0.0);
    // The source map is affine on each island and the target is parallel to it: exact.
    EXPECT_LT(seam.angleMax, 1 + 1e-6);
    EXPECT_LT(seam.areaMax, 1 + 1e-6);
    EXPECT_LT(seam.uvErrorMax, 1e-9);
    // The seam edges lie on x = 1 cm.
    for (const auto& [a, b] : cut.seamEdges) {
        EXPECT_NEAR(cut.mesh.positions()[a].x(), 0.01, 1e-9);
        EXPECT_NEAR(cut.mesh.positions()[b].x(), 0.01, 1e-9);
    }
}

TEST(bake_uv_transfer, ASeamInsideOneIslandStretchesTheLabelledTransferButNotTheCut) {
    const bake::UvSource source({unwrappedTube(32)});
    const sim::TriMesh target = tubeTarget(17); // its vertices never on the seam's angle
    const auto labelled = bake::measureUvTransfer(
        source, target, bake::transferUv(source, target, bake::UvTransferMethod::IslandLabelled), 4000);
    EXPECT_EQ(labelled.spanningIslands, 0u); // one island: the label cannot help (Fig. 3.4 case 3)
    EXPECT_GT(labelled.seamCrossed, 0u);
    EXPECT_GT(labelled.overThreshold, 0.0);
    EXPECT_GT(labelled.uvErrorMax, 0.2);

    bake::SeamCutReport report;
    const bake::UvMesh cut = bake::cutAlongSeams(source, target, {}, &report);
    const auto seam = bake::measureUvTransfer(
        source, cut.mesh, bake::transferUv(source, cut.mesh, bake::UvTransferMethod::SeamCutting), 4000);
    EXPECT_EQ(seam.seamCrossed, 0u);
    EXPECT_EQ(seam.flipped, 0u);
    EXPECT_EQ(seam.overThreshold, 0.0);
    EXPECT_LT(seam.angleP95, 1.2); // a 17-gon against a 32-gon: chords, not a seam
    EXPECT_LT(seam.uvErrorMax, 0.02);
}

TEST(bake_uv_transfer, BadUvsAndParametersAreRefusedByName) {
    bake::RemeshPart part = sheetWithTwoIslands();
    part.uv.pop_back();
    EXPECT_THAT([&] { bake::UvSource s({part}); }, ::testing::ThrowsMessage<InputError>(HasSubstr("sheet: 127 UV")));
    part = sheetWithTwoIslands();
    part.uv[3][1] = Vec2(std::nan(""), 0);
    EXPECT_THAT([&] { bake::UvSource s({part}); },
                ::testing::ThrowsMessage<InputError>(HasSubstr("sheet: triangle 3 corner 1: UV is not finite")));
    part.uv.clear();
    EXPECT_THAT([&] { bake::UvSource s({part}); },
                ::testing::ThrowsMessage<InputError>(HasSubstr("sheet: the part has no UVs")));
    const bake::UvSource source({sheetWithTwoIslands()});
    bake::SeamCutParams bad;
    bad.snapFraction = 0.5;
    EXPECT_THROW(bake::cutAlongSeams(source, grid(3), bad), std::invalid_argument);
}

TEST(bake_uv_transfer, TheKidneySampleKeepsItsUvsThroughTheRemesh) {
    const std::vector<bake::RemeshPart> parts = bake::kidneyAnatomy(48);
    for (const bake::RemeshPart& p : parts)
        ASSERT_EQ(p.uv.size(), p.surface.triangleCount()) << p.name;
    const bake::UvSource source(parts);
    EXPECT_EQ(source.islandCount(), 7u); // cortex 1, pelvis 2, ureter 1, artery 3
    bake::RemeshParams params;
    params.voxelCount = 64;
    const bake::RemeshResult r = bake::voxelRemesh(parts, params);
    ASSERT_TRUE(r.report.uvTransferred);
    EXPECT_TRUE(r.report.closed);
    EXPECT_TRUE(r.report.manifold);
    EXPECT_EQ(r.report.selfIntersections, 0u);
    ASSERT_EQ(r.uv.size(), r.mesh.triangleCount());
    EXPECT_GT(r.seamEdges.size(), 0u);
    for (const bake::CornerUv& c : r.uv)
        for (const Vec2& u : c)
            ASSERT_TRUE(u.allFinite());
    const auto seam = bake::measureUvTransfer(source, r.mesh, r.uv, 5000);
    const auto closest = bake::measureUvTransfer(
        source, r.uncut, bake::transferUv(source, r.uncut, bake::UvTransferMethod::ClosestPoint), 5000);
    EXPECT_GT(closest.spanningIslands, 0u);
    EXPECT_EQ(seam.spanningIslands, 0u);
    EXPECT_LT(seam.overThreshold, closest.overThreshold);
    EXPECT_LT(seam.uvErrorP95, closest.uvErrorP95 + 1e-12);
}
