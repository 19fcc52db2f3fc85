// Mean-curvature-flow skeletons [A §4.3.5]: a straight tube gives a centred path, a bent tube a
// centred path along its arc, a torus a single centred loop; boundaries of tet meshes map every
// tet node (100 % coverage) and paint finite positive weights; bad surfaces are rejected.
// The time to skeletonize the ~5k-triangle tube is recorded as the test property
// "skeletonize_tube_4896_tris_seconds" (see the XML output); nothing is asserted on it.
#include "bake/skeleton.hpp"
#include "bake/tetrahedralize.hpp"

#include "sim/mesh/generators.hpp"
#include "sim/skeleton/node_weights_io.hpp"
#include "sim/skeleton/stiffness_paint.hpp"
#include "sim/util/error.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>

using namespace viscera;
using ::testing::HasSubstr;

namespace {

constexpr double kRadius = 0.01; // m
constexpr double kLength = 0.1;  // m

/// Closed torus around the z axis (major radius R, minor radius r), outward oriented.
sim::TriMesh torusSurface(double R, double r, int nu, int nv) {
    std::vector<sim::Vec3> pos;
    std::vector<sim::Tri> tris;
    for (int i = 0; i < nu; ++i)
        for (int j = 0; j < nv; ++j) {
            const double u = 2 * std::numbers::pi * i / nu, v = 2 * std::numbers::pi * j / nv;
            pos.emplace_back((R + r * std::cos(v)) * std::cos(u), (R + r * std::cos(v)) * std::sin(u), r * std::sin(v));
        }
    auto id = [&](int i, int j) { return static_cast<int32_t>((i % nu) * nv + (j % nv)); };
    for (int i = 0; i < nu; ++i)
        for (int j = 0; j < nv; ++j) {
            tris.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
            tris.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
        }
    sim::TriMesh m = sim::TriMesh::fromArrays(pos, tris);
    if (m.signedVolume() < 0) {
        for (auto& t : tris)
            std::swap(t[1], t[2]);
        m = sim::TriMesh::fromArrays(pos, tris);
    }
    return m;
}

/// Closed tube of radius r bent along a half circle of radius R in the xy plane (θ from 0 to π),
/// capped by triangle fans.
sim::TriMesh bentTubeSurface(double R, double r, int rings, int slices) {
    std::vector<sim::Vec3> pos;
    std::vector<sim::Tri> tris;
    for (int k = 0; k <= rings; ++k) {
        const double t = std::numbers::pi * k / rings;
        const sim::Vec3 c(R * std::cos(t), R * std::sin(t), 0), er(std::cos(t), std::sin(t), 0);
        for (int s = 0; s < slices; ++s) {
            const double p = 2 * std::numbers::pi * s / slices;
            pos.push_back(c + r * (std::cos(p) * er + std::sin(p) * sim::Vec3::UnitZ()));
        }
    }
    auto id = [&](int k, int s) { return static_cast<int32_t>(k * slices + s % slices); };
    for (int k = 0; k < rings; ++k)
        for (int s = 0; s < slices; ++s) {
            tris.push_back({id(k, s), id(k + 1, s), id(k + 1, s + 1)});
            tris.push_back({id(k, s), id(k + 1, s + 1), id(k, s + 1)});
        }
    const auto c0 = static_cast<int32_t>(pos.size());
    pos.emplace_back(R, 0, 0);
    const auto c1 = static_cast<int32_t>(pos.size());
    pos.emplace_back(-R, 0, 0);
    for (int s = 0; s < slices; ++s) {
        tris.push_back({c0, id(0, s), id(0, s + 1)});
        tris.push_back({c1, id(rings, s + 1), id(rings, s)});
    }
    sim::TriMesh m = sim::TriMesh::fromArrays(pos, tris);
    if (m.signedVolume() < 0) {
        for (auto& t : tris)
            std::swap(t[1], t[2]);
        m = sim::TriMesh::fromArrays(pos, tris);
    }
    return m;
}

/// A connected tree whose nodes all have degree <= 2 with exactly two ends: a simple path.
void expectPath(const sim::Skeleton& s) {
    std::vector<int32_t> comp;
    EXPECT_EQ(s.components(comp), 1);
    EXPECT_EQ(s.cycleRank(), 0);
    const auto deg = s.degrees();
    EXPECT_LE(*std::max_element(deg.begin(), deg.end()), 2);
    EXPECT_EQ(std::count(deg.begin(), deg.end(), 1), 2);
}

void expectEverySurfaceVertexMapped(const sim::Skeleton& s, const bake::SkeletonReport& r) {
    EXPECT_EQ(r.unlistedVertices, 0u);
    for (size_t v = 0; v < s.vertexNode.size(); ++v) {
        ASSERT_GE(s.vertexNode[v], 0) << "vertex " << v;
        ASSERT_LT(s.vertexNode[v], static_cast<int32_t>(s.nodes.size()));
    }
}

std::string inputError(const sim::TriMesh& s) {
    bake::SkeletonParams p;
    p.label = "vessel.obj";
    try {
        bake::extractSkeleton(s, p);
    } catch (const InputError& e) {
        return e.what();
    }
    return "no error";
}

bake::MeshingParams coarse(double size) {
    bake::MeshingParams p;
    p.facetSize = size;
    p.cellSize = size;
    p.facetDistance = size / 20;
    return p;
}

} // namespace

TEST(bake_skeleton, StraightTubeGivesACentredPath) {
    const sim::TriMesh tube =
        sim::makeTubeSurface(sim::Vec3(0.02, -0.01, 0.03), sim::Vec3(0.02, -0.01, 0.03 + kLength), kRadius, 48, 50);
    ASSERT_EQ(tube.triangleCount(), 4896u);
    const bake::SkeletonResult r = bake::extractSkeleton(tube);
    RecordProperty("skeletonize_tube_4896_tris_seconds", std::to_string(r.report.seconds));
    RecordProperty("skeleton_nodes", static_cast<int>(r.report.nodes));
    RecordProperty("skeleton_scratch_bytes", std::to_string(r.report.scratchBytes));
    const sim::Skeleton& s = r.skeleton;
    ASSERT_GE(s.nodes.size(), 5u);
    EXPECT_EQ(r.report.nodes, s.nodes.size());
    EXPECT_EQ(r.report.edges, s.edges.size());
    EXPECT_EQ(r.report.surfaceTriangles, 4896u);
    expectPath(s);
    expectEverySurfaceVertexMapped(s, r.report);
    double zmin = HUGE_VAL, zmax = -HUGE_VAL;
    for (const sim::Vec3& p : s.nodes) {
        const double axial = std::hypot(p.x() - 0.02, p.y() + 0.01);
        EXPECT_LT(axial, 0.1 * kRadius) << "node off the axis: " << p.transpose();
        zmin = std::min(zmin, p.z());
        zmax = std::max(zmax, p.z());
    }
    EXPECT_GE(zmin, 0.03 - 0.05 * kRadius);
    EXPECT_LE(zmax, 0.03 + kLength + 0.05 * kRadius);
    EXPECT_GT(zmax - zmin, kLength - 2.5 * kRadius); // the ends retract by about a radius
    // Correspondence: a side vertex maps to a node near its own cross-section.
    for (size_t v = 0; v < tube.vertexCount(); ++v) {
        const sim::Vec3& x = tube.positions()[v];
        const double z = std::clamp(x.z(), zmin, zmax);
        EXPECT_LT(std::abs(s.nodes[s.vertexNode[v]].z() - z), 1.5 * kRadius) << "vertex " << v;
    }
}

TEST(bake_skeleton, SameSurfaceSameSkeletonAtAnyScale) {
    // Bit-identical repeat runs; millimetre-sized and metre-sized tubes give the same shape.
    const sim::TriMesh small = sim::makeTubeSurface(sim::Vec3::Zero(), sim::Vec3(0, 0, 0.02), 0.002, 24, 20);
    const bake::SkeletonResult a = bake::extractSkeleton(small);
    const bake::SkeletonResult b = bake::extractSkeleton(small);
    EXPECT_EQ(a.skeleton.nodes, b.skeleton.nodes);
    EXPECT_EQ(a.skeleton.edges, b.skeleton.edges);
    EXPECT_EQ(a.skeleton.vertexNode, b.skeleton.vertexNode);
    expectPath(a.skeleton);
    const sim::TriMesh big = sim::makeTubeSurface(sim::Vec3::Zero(), sim::Vec3(0, 0, 20), 2, 24, 20);
    const bake::SkeletonResult c = bake::extractSkeleton(big);
    expectPath(c.skeleton);
    for (const sim::Vec3& p : a.skeleton.nodes)
        EXPECT_LT(std::hypot(p.x(), p.y()), 0.1 * 0.002);
    for (const sim::Vec3& p : c.skeleton.nodes)
        EXPECT_LT(std::hypot(p.x(), p.y()), 0.1 * 2);
}

TEST(bake_skeleton, BentTubeFollowsItsArc) {
    const double R = 0.05, r = 0.008;
    const sim::TriMesh tube = bentTubeSurface(R, r, 60, 24);
    const bake::SkeletonResult res = bake::extractSkeleton(tube);
    const sim::Skeleton& s = res.skeleton;
    expectPath(s);
    expectEverySurfaceVertexMapped(s, res.report);
    double tmin = HUGE_VAL, tmax = -HUGE_VAL;
    for (const sim::Vec3& p : s.nodes) {
        const double fromArc = std::hypot(std::hypot(p.x(), p.y()) - R, p.z());
        EXPECT_LT(fromArc, 0.25 * r) << p.transpose(); // MCF pulls slightly towards the bend's inside
        const double t = std::atan2(p.y(), p.x());
        tmin = std::min(tmin, t);
        tmax = std::max(tmax, t);
    }
    EXPECT_GT(tmax - tmin, std::numbers::pi - 3 * r / R); // covers the arc but the end retraction
}

TEST(bake_skeleton, TorusGivesOneCentredLoop) {
    const double R = 0.05, r = 0.012;
    const bake::SkeletonResult res = bake::extractSkeleton(torusSurface(R, r, 64, 24));
    const sim::Skeleton& s = res.skeleton;
    EXPECT_EQ(res.report.cycleRank, 1);
    EXPECT_EQ(res.report.components, 1);
    const auto deg = s.degrees();
    for (int32_t d : deg)
        EXPECT_EQ(d, 2);
    expectEverySurfaceVertexMapped(s, res.report);
    for (const sim::Vec3& p : s.nodes)
        EXPECT_LT(std::hypot(std::hypot(p.x(), p.y()) - R, p.z()), 0.15 * r);
}

TEST(bake_skeleton, TetTubeBoundaryMapsEveryNodeAndPaints) {
    bake::TetrahedralizeResult tet = bake::tetrahedralize(
        sim::makeTubeSurface(sim::Vec3::Zero(), sim::Vec3(0, 0, 0.08), kRadius, 32, 24), coarse(0.004));
    sim::TetMesh& mesh = *tet.mesh;
    const bake::SkeletonResult sk = bake::extractSkeleton(mesh);
    const sim::Skeleton& s = sk.skeleton;
    ASSERT_EQ(s.vertexNode.size(), mesh.vertexCount());
    // The boundary of a Delaunay-refined tube has sharp protected rims; the skeleton is a tree
    // along the axis (a short spur may sprout near an end cap, so no strict path here).
    std::vector<int32_t> comp;
    EXPECT_EQ(s.components(comp), 1);
    EXPECT_EQ(s.cycleRank(), 0);
    size_t interior = 0;
    for (size_t v = 0; v < mesh.vertexCount(); ++v) {
        const bool boundary = mesh.isBoundaryVertex(static_cast<int32_t>(v));
        EXPECT_EQ(s.vertexNode[v] != sim::kNone, boundary) << "vertex " << v;
        interior += !boundary;
    }
    EXPECT_GT(interior, 10u);
    for (const sim::Vec3& p : s.nodes)
        EXPECT_LT(std::hypot(p.x(), p.y()), 0.15 * kRadius);

    const sim::SkeletonNodeMap map = sim::mapNodesToSkeleton(mesh, s);
    EXPECT_EQ(map.coveredCount(), mesh.vertexCount()) << "coverage must be 100 %";
    RecordProperty("tube_fallback_nodes", static_cast<int>(map.fallbackNodes.size()));
    RecordProperty("tube_nodes", static_cast<int>(mesh.vertexCount()));

    // Stiffen the middle, soften one end: finite, positive, bounded, repeatable.
    const std::vector<sim::BrushStroke> strokes = {{sim::Vec3(0, 0, 0.04), 0.02, 4.0, sim::BrushScale::Peak},
                                                   {sim::Vec3(0, 0, 0.0), 0.02, -0.8, sim::BrushScale::Peak}};
    const sim::StiffnessPaintResult paint = sim::bakeStiffnessPaint(mesh, s, strokes);
    ASSERT_EQ(paint.weights.size(), mesh.vertexCount());
    size_t stiffer = 0, softer = 0;
    for (size_t v = 0; v < mesh.vertexCount(); ++v) {
        const double w = paint.weights[v];
        ASSERT_TRUE(std::isfinite(w));
        EXPECT_GE(w, 1e-3);
        EXPECT_LE(w, 5.0 + 1e-12);
        stiffer += w > 1.0;
        softer += w < 1.0;
        const sim::Vec3& x = mesh.positions()[v];
        if (std::abs(x.z() - 0.04) < 0.005 && std::hypot(x.x(), x.y()) < 0.004) {
            EXPECT_GT(w, 3.0) << "near the centre of the stiffening stroke";
        }
    }
    EXPECT_GT(stiffer, 20u);
    EXPECT_GT(softer, 20u);
    EXPECT_EQ(sim::bakeStiffnessPaint(mesh, s, strokes).weights, paint.weights);

    // Into the case: the weights file round-trips exactly.
    const auto dir = std::filesystem::temp_directory_path() / "viscera_test_bake_skeleton";
    std::filesystem::create_directories(dir);
    sim::writeNodeWeights(dir / "tube.vweights", paint.weights);
    EXPECT_EQ(sim::readNodeWeights(dir / "tube.vweights", mesh.vertexCount()), paint.weights);
    std::filesystem::remove_all(dir);
}

TEST(bake_skeleton, BlobBoundaryMapsEveryNode) {
    bake::TetrahedralizeResult tet = bake::tetrahedralize(
        sim::makeLiverSurface(sim::Vec3(0.1, 0, 0), sim::Vec3(0.08, 0.04, 0.03), 0.5, 48, 24), coarse(0.008));
    const bake::SkeletonResult sk = bake::extractSkeleton(*tet.mesh);
    std::vector<int32_t> comp;
    EXPECT_EQ(sk.skeleton.components(comp), 1);
    EXPECT_EQ(sk.skeleton.cycleRank(), 0); // genus 0 surface: a tree
    const sim::SkeletonNodeMap map = sim::mapNodesToSkeleton(*tet.mesh, sk.skeleton);
    EXPECT_EQ(map.coveredCount(), tet.mesh->vertexCount()) << "coverage must be 100 %";
    RecordProperty("blob_fallback_nodes", static_cast<int>(map.fallbackNodes.size()));
    // Every node lies inside the surface's bounding box (the skeleton is inside the shape).
    const auto box = tet.mesh->boundary().bounds();
    for (const sim::Vec3& p : sk.skeleton.nodes) {
        EXPECT_TRUE((p.array() >= box[0].array()).all() && (p.array() <= box[1].array()).all()) << p.transpose();
    }
}

TEST(bake_skeleton, BadSurfacesAreRejectedNamingTheRule) {
    const sim::TriMesh tube = sim::makeTubeSurface(sim::Vec3::Zero(), sim::Vec3(0, 0, 0.05), 0.01, 12, 6);
    EXPECT_EQ(inputError(sim::TriMesh{}), "vessel.obj: surface has no triangles");

    std::vector<sim::Tri> tris = tube.triangles();
    tris.pop_back();
    EXPECT_THAT(inputError(sim::TriMesh::fromArrays(tube.positions(), tris)),
                HasSubstr("vessel.obj: surface is not closed: edge"));

    tris = tube.triangles();
    std::swap(tris[5][1], tris[5][2]);
    EXPECT_THAT(inputError(sim::TriMesh::fromArrays(tube.positions(), tris)),
                HasSubstr("surface is not consistently oriented"));

    tris = tube.triangles();
    tris.push_back(tris[0]);
    EXPECT_THAT(inputError(sim::TriMesh::fromArrays(tube.positions(), tris)),
                HasSubstr("surface is not manifold: edge"));

    std::vector<sim::Vec3> pos = tube.positions();
    const sim::Tri t0 = tube.triangles()[0];
    pos[t0[0]] = 0.5 * (pos[t0[1]] + pos[t0[2]]);
    EXPECT_EQ(inputError(sim::TriMesh::fromArrays(pos, tube.triangles())),
              "vessel.obj: triangle 0 is degenerate (zero area)");

    // Two boxes sharing one corner vertex: a non-manifold vertex.
    const sim::TriMesh b1 = sim::makeBoxSurface(sim::Vec3::Zero(), sim::Vec3::Constant(0.01));
    const sim::TriMesh b2 = sim::makeBoxSurface(sim::Vec3::Constant(0.01), sim::Vec3::Constant(0.02));
    pos = b1.positions();
    tris = b1.triangles();
    std::vector<int32_t> remap(8);
    for (int k = 0; k < 8; ++k) {
        if (k == 0) {
            remap[k] = 7; // b2's min corner is b1's max corner
            continue;
        }
        remap[k] = static_cast<int32_t>(pos.size());
        pos.push_back(b2.positions()[k]);
    }
    for (const sim::Tri& t : b2.triangles())
        tris.push_back({remap[t[0]], remap[t[1]], remap[t[2]]});
    EXPECT_EQ(inputError(sim::TriMesh::fromArrays(pos, tris)),
              "vessel.obj: surface is not manifold at vertex 7: its triangles form more than one fan (surfaces "
              "touch there)");

    // Two overlapping boxes: self-intersection.
    const sim::TriMesh b3 = sim::makeBoxSurface(sim::Vec3::Constant(0.005), sim::Vec3::Constant(0.015));
    pos = b1.positions();
    tris = b1.triangles();
    for (const sim::Vec3& p : b3.positions())
        pos.push_back(p);
    for (const sim::Tri& t : b3.triangles())
        tris.push_back({t[0] + 8, t[1] + 8, t[2] + 8});
    EXPECT_THAT(inputError(sim::TriMesh::fromArrays(pos, tris)), HasSubstr("vessel.obj: surface self-intersects"));
}

TEST(bake_skeleton, ParametersAreChecked) {
    const sim::TriMesh tube = sim::makeTubeSurface(sim::Vec3::Zero(), sim::Vec3(0, 0, 0.05), 0.01, 12, 6);
    auto error = [&](bake::SkeletonParams p) -> std::string {
        try {
            bake::extractSkeleton(tube, p);
        } catch (const std::invalid_argument& e) {
            return e.what();
        }
        return "no error";
    };
    bake::SkeletonParams p;
    p.maxTriangleAngleDeg = 80;
    EXPECT_EQ(error(p),
              "bake::extractSkeleton(): SkeletonParams::maxTriangleAngleDeg is 80.000000 (must be in (90, 180))");
    p = {};
    p.minEdgeLengthRel = 0;
    EXPECT_THAT(error(p), HasSubstr("SkeletonParams::minEdgeLengthRel"));
    p = {};
    p.areaVariationFactor = 1.5;
    EXPECT_THAT(error(p), HasSubstr("SkeletonParams::areaVariationFactor"));
    p = {};
    p.maxIterations = 0;
    EXPECT_THAT(error(p), HasSubstr("SkeletonParams::maxIterations"));
    p = {};
    p.qualitySpeedTradeoff = NAN;
    EXPECT_THAT(error(p), HasSubstr("SkeletonParams::qualitySpeedTradeoff"));
    p = {};
    p.mediallyCenteredSpeedTradeoff = -1;
    EXPECT_THAT(error(p), HasSubstr("SkeletonParams::mediallyCenteredSpeedTradeoff"));
}
