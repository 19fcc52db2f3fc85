// Voxel remesh (bake/remesh.hpp): CSG of overlapping, open parts into one closed, manifold,
// self-intersection-free surface; its figures against the analytic volumes of boxes; caps,
// parameter rules, cancellation; the result tetrahedralizes.
#include "bake/import.hpp"
#include "bake/remesh.hpp"
#include "bake/sample_anatomy.hpp"
#include "bake/tetrahedralize.hpp"

#include "sim/mesh/generators.hpp"
#include "sim/util/error.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

using namespace viscera;
using ::testing::HasSubstr;
namespace fs = std::filesystem;

namespace {

sim::TriMesh box(double x0, double y0, double z0, double size) {
    return sim::makeBoxSurface(sim::Vec3(x0, y0, z0), sim::Vec3(x0 + size, y0 + size, z0 + size));
}

/// A box with the two triangles of one face removed: open, no inside.
sim::TriMesh openBox(double x0, double y0, double z0, double size) {
    const sim::TriMesh b = box(x0, y0, z0, size);
    std::vector<sim::Tri> tris;
    for (const sim::Tri& t : b.triangles()) {
        bool top = true;
        for (int32_t v : t)
            top = top && b.positions()[v].z() > z0 + 0.5 * size;
        if (!top) tris.push_back(t);
    }
    return sim::TriMesh::fromArrays(b.positions(), tris);
}

bake::RemeshParams params(int voxels = 64) {
    bake::RemeshParams p;
    p.voxelCount = voxels;
    return p;
}

// Two 2 cm cubes overlapping in a 1 cm cube.
std::vector<bake::RemeshPart> twoCubes(bake::CsgOp op) {
    return {{"a", box(0, 0, 0, 0.02), bake::CsgOp::Union, {}}, {"b", box(0.01, 0.01, 0.01, 0.02), op, {}}};
}

void expectSound(const bake::RemeshResult& r) {
    EXPECT_TRUE(r.report.closed);
    EXPECT_TRUE(r.report.manifold);
    EXPECT_EQ(r.report.selfIntersections, 0u);
    EXPECT_TRUE(r.mesh.isClosedOriented());
    EXPECT_GT(r.mesh.signedVolume(), 0);
}

/// The remeshed surface tetrahedralizes at (cell, facet) into at least minTets tets, none inverted.
bake::TetrahedralizeResult expectTetrahedralizes(const bake::RemeshResult& r, double cell, double facet,
                                                 size_t minTets) {
    bake::MeshingParams m;
    m.cellSize = cell;
    m.facetSize = facet;
    bake::TetrahedralizeResult t = bake::tetrahedralize(r.mesh, m);
    EXPECT_GT(t.mesh->tetCount(), minTets);
    EXPECT_TRUE(t.report.quality.inverted.empty());
    return t;
}

/// The parts carry these names in order and a UV triangle each, inside the unit square.
void expectNamedPartsWithUvs(const std::vector<bake::RemeshPart>& parts, const std::vector<std::string>& names) {
    ASSERT_EQ(parts.size(), names.size());
    for (size_t i = 0; i < parts.size(); ++i) {
        EXPECT_EQ(parts[i].name, names[i]);
        ASSERT_EQ(parts[i].uv.size(), parts[i].surface.triangleCount()) << names[i] << ": a UV triangle each";
        for (const bake::CornerUv& c : parts[i].uv)
            for (const auto& uv : c)
                EXPECT_TRUE(uv.x() >= 0 && uv.x() <= 1 && uv.y() >= 0 && uv.y() <= 1) << names[i];
    }
}

} // namespace

TEST(bake_remesh, UnionOfOverlappingCubesIsOneClosedSurfaceOfTheirVolume) {
    const bake::RemeshResult r = bake::voxelRemesh(twoCubes(bake::CsgOp::Union), params());
    expectSound(r);
    const double exact = 2 * 8e-6 - 1e-6; // overlap counted once
    EXPECT_NEAR(r.report.volume, exact, 0.02 * exact);
    EXPECT_NEAR(r.report.sourceVolume, 16e-6, 1e-12); // the parts, overlap twice
    const double voxelMm = r.report.voxelSize * 1e3;
    EXPECT_NEAR(voxelMm, 30.0 / 64, 1e-9); // 3 cm longest axis / 64
    EXPECT_LT(r.report.distanceMeanMm, 0.25 * voxelMm);
    EXPECT_LT(r.report.distanceMaxMm, 1.5 * voxelMm);
    EXPECT_GT(r.report.featureEdges, 0u); // the cube edges are held while remeshing
    EXPECT_LT(std::abs(r.report.volumeChangeFromIso), 0.01);
    EXPECT_EQ(r.report.triangles, r.mesh.triangleCount());
}

TEST(bake_remesh, DifferenceAndIntersectionGiveTheirVolumes) {
    const bake::RemeshResult d = bake::voxelRemesh(twoCubes(bake::CsgOp::Difference), params());
    expectSound(d);
    EXPECT_NEAR(d.report.volume, 7e-6, 0.03 * 7e-6);
    const bake::RemeshResult i = bake::voxelRemesh(twoCubes(bake::CsgOp::Intersection), params());
    expectSound(i);
    EXPECT_NEAR(i.report.volume, 1e-6, 0.05 * 1e-6);
}

TEST(bake_remesh, AnOpenPartIsThickenedIntoAClosedShell) {
    std::vector<bake::RemeshPart> parts{{"open", openBox(0, 0, 0, 0.02), bake::CsgOp::Union, {}}};
    ASSERT_FALSE(parts[0].surface.isClosedOriented());
    const bake::RemeshResult r = bake::voxelRemesh(parts, params());
    expectSound(r);
    EXPECT_EQ(r.report.openParts, 1u);
    // A shell 1.5 voxels thick over the five faces (5 × 4 cm²), far less than the box's 8 cm³.
    const double shell = 5 * 4e-4 * 1.5 * r.report.voxelSize;
    EXPECT_NEAR(r.report.volume, shell, 0.35 * shell);
    EXPECT_LT(r.report.distanceMaxMm, 2.0 * r.report.voxelSize * 1e3);
}

// An open tube (a duct as bought anatomy has it: no end caps) with its openings filled becomes a
// solid cylinder of the tube's volume; openings wider than the limit leave it a hollow shell.
TEST(bake_remesh, OpeningsUpToTheFillWidthAreCappedAndTheTubeIsSolid) {
    const sim::Vec3 a(0, 0, 0), b(0.03, 0, 0);
    const double radius = 0.004;
    const sim::TriMesh closed = sim::makeTubeSurface(a, b, radius, 24, 12);
    std::vector<sim::Tri> open; // the caps off: triangles with all corners on an end plane
    for (const sim::Tri& t : closed.triangles()) {
        bool cap = true;
        for (const double end : {0.0, 0.03}) {
            bool onEnd = true;
            for (int32_t v : t)
                onEnd = onEnd && std::abs(closed.positions()[v].x() - end) < 1e-9;
            cap = cap && !onEnd;
        }
        if (cap) open.push_back(t);
    }
    std::vector<bake::RemeshPart> parts{
        {"duct", sim::TriMesh::fromArrays(closed.positions(), open), bake::CsgOp::Union, {}}};
    ASSERT_FALSE(parts[0].surface.isClosedOriented());
    bake::RemeshParams p = params(96);
    p.fillOpenings = 0.012; // the 8 mm openings' box diagonal is 11.3 mm
    const bake::RemeshResult filled = bake::voxelRemesh(parts, p);
    expectSound(filled);
    EXPECT_EQ(filled.report.filledParts, 1u);
    EXPECT_EQ(filled.report.openParts, 0u);
    const double solid = M_PI * radius * radius * 0.03;
    EXPECT_NEAR(filled.report.volume, solid, 0.08 * solid);
    p.fillOpenings = 0.01; // narrower than the openings: a shell
    const bake::RemeshResult shell = bake::voxelRemesh(parts, p);
    expectSound(shell);
    EXPECT_EQ(shell.report.filledParts, 0u);
    EXPECT_EQ(shell.report.openParts, 1u);
    EXPECT_LT(shell.report.volume, 0.7 * solid);
    p.fillOpenings = -1;
    EXPECT_THROW(bake::voxelRemesh(parts, p), std::invalid_argument);
}

TEST(bake_remesh, TheResultTetrahedralizes) {
    const bake::RemeshResult r = bake::voxelRemesh(twoCubes(bake::CsgOp::Union), params(48));
    const bake::TetrahedralizeResult t = expectTetrahedralizes(r, 0.003, 0.002, 100);
    EXPECT_NEAR(t.report.tetVolume, r.report.volume, 0.03 * r.report.volume);
}

TEST(bake_remesh, RunsAreRepeatable) {
    const bake::RemeshResult a = bake::voxelRemesh(twoCubes(bake::CsgOp::Union), params(40));
    const bake::RemeshResult b = bake::voxelRemesh(twoCubes(bake::CsgOp::Union), params(40));
    ASSERT_EQ(a.mesh.vertexCount(), b.mesh.vertexCount());
    ASSERT_EQ(a.mesh.triangleCount(), b.mesh.triangleCount());
    EXPECT_EQ(a.mesh.positions(), b.mesh.positions());
    EXPECT_EQ(a.mesh.triangles(), b.mesh.triangles());
}

TEST(bake_remesh, CapsAndParameterRulesNameThemselves) {
    bake::RemeshParams p = params();
    p.voxelSize = 1e-5; // 3 cm / 10 µm = 3000 voxels
    try {
        bake::voxelRemesh(twoCubes(bake::CsgOp::Union), p);
        ADD_FAILURE() << "a 3000-voxel grid was accepted";
    } catch (const InputError& e) {
        EXPECT_THAT(e.what(), HasSubstr("cap RemeshParams::maxVoxelsPerAxis = 2048"));
    }
    p = params();
    p.maxTriangles = 100;
    try {
        bake::voxelRemesh(twoCubes(bake::CsgOp::Union), p);
        ADD_FAILURE() << "the triangle cap was not applied";
    } catch (const InputError& e) {
        EXPECT_THAT(e.what(), HasSubstr("cap RemeshParams::maxTriangles = 100"));
    }
    p = params(4);
    EXPECT_THROW(bake::voxelRemesh(twoCubes(bake::CsgOp::Union), p), std::invalid_argument);
    p = params();
    p.bandVoxels = 2;
    try {
        bake::voxelRemesh(twoCubes(bake::CsgOp::Union), p);
        ADD_FAILURE();
    } catch (const std::invalid_argument& e) {
        EXPECT_THAT(e.what(), HasSubstr("RemeshParams::bandVoxels must be in [3, 16]"));
    }
    // Disjoint parts intersect in nothing.
    std::vector<bake::RemeshPart> apart{{"a", box(0, 0, 0, 0.01), bake::CsgOp::Union, {}},
                                        {"b", box(0.02, 0, 0, 0.01), bake::CsgOp::Intersection, {}}};
    try {
        bake::voxelRemesh(apart, params(32));
        ADD_FAILURE();
    } catch (const InputError& e) {
        EXPECT_THAT(e.what(), HasSubstr("the combined volume is empty"));
    }
}

TEST(bake_remesh, ProgressCanCancelAndReportsEveryStage) {
    std::vector<std::string> stages;
    double last = -1;
    bool rising = true;
    bake::voxelRemesh(twoCubes(bake::CsgOp::Union), params(32), [&](std::string_view s, double f) {
        stages.emplace_back(s);
        rising = rising && f >= last && f <= 1.0;
        last = f;
        return true;
    });
    EXPECT_TRUE(rising);
    ASSERT_GE(stages.size(), 6u);
    EXPECT_EQ(stages.front(), "level set 1/2: a");
    EXPECT_EQ(stages.back(), "done");
    EXPECT_THAT(stages, ::testing::Contains("isosurface"));
    EXPECT_THROW(bake::voxelRemesh(twoCubes(bake::CsgOp::Union), params(32),
                                   [](std::string_view s, double) { return s != "isosurface"; }),
                 bake::RemeshCancelled);
    std::atomic<bool> cancel{true};
    EXPECT_THROW(bake::voxelRemesh(twoCubes(bake::CsgOp::Union), params(32), {}, &cancel), bake::RemeshCancelled);
}

TEST(bake_remesh, TheObjWriterRoundTrips) {
    const bake::RemeshResult r = bake::voxelRemesh(twoCubes(bake::CsgOp::Union), params(24));
    const fs::path file = fs::path(::testing::TempDir()) / ("viscera_remesh_" + std::to_string(::getpid()) + ".obj");
    bake::writeObj(file.string(), r.mesh);
    const sim::TriMesh back = bake::importSurface(file);
    fs::remove(file);
    EXPECT_EQ(back.vertexCount(), r.mesh.vertexCount());
    EXPECT_EQ(back.triangleCount(), r.mesh.triangleCount());
    EXPECT_NEAR(back.signedVolume(), r.mesh.signedVolume(), 1e-6 * r.mesh.signedVolume());
}

TEST(bake_remesh, HolesOfAtMostThreeVoxelsAreClosedWiderOnesThickened) {
    const sim::TriMesh closed = box(0, 0, 0, 0.02);
    EXPECT_EQ(bake::detail::largestHoleDiameter(closed), 0.0);
    EXPECT_NEAR(bake::detail::largestHoleDiameter(openBox(0, 0, 0, 0.02)), 0.02 * std::sqrt(2.0), 1e-12);
    // A fine ellipsoid (triangles of about 1.5 mm) with one triangle missing: a hole of at most
    // 2.4 mm, under three voxels of 1.5 mm, so the part keeps its inside; at 0.25 mm voxels the same
    // hole is wider than three voxels and the part is thickened instead.
    const sim::TriMesh e = sim::makeEllipsoidSurface(sim::Vec3::Zero(), sim::Vec3(0.03, 0.02, 0.015), 128, 64);
    std::vector<sim::Tri> tris = e.triangles();
    tris.erase(tris.begin() + long(tris.size() / 3));
    std::vector<bake::RemeshPart> parts{{"e", sim::TriMesh::fromArrays(e.positions(), tris), bake::CsgOp::Union, {}}};
    const double hole = bake::detail::largestHoleDiameter(parts[0].surface);
    EXPECT_GT(hole, 0.001);
    EXPECT_LT(hole, 0.0024);
    const bake::RemeshResult r = bake::voxelRemesh(parts, params(40));
    expectSound(r);
    EXPECT_EQ(r.report.closedHoles, 1u);
    EXPECT_EQ(r.report.openParts, 0u);
    const double exact = 4.0 / 3.0 * M_PI * 0.03 * 0.02 * 0.015;
    EXPECT_NEAR(r.report.volume, exact, 0.04 * exact);
    EXPECT_NEAR(r.report.sourceVolume, exact, 0.01 * exact);
    bake::RemeshParams fine = params(240);
    fine.remeshIterations = 0;
    const bake::RemeshResult shell = bake::voxelRemesh(parts, fine);
    EXPECT_EQ(shell.report.openParts, 1u);
    EXPECT_EQ(shell.report.closedHoles, 0u);
    // The 1.5-voxel shell closes over the hole, and the level set of a closed shell holds its
    // cavity too: the part is solid again, a shell's thickness larger.
    EXPECT_GT(shell.report.volume, exact);
    EXPECT_LT(shell.report.volume, 1.12 * exact);
}

TEST(bake_remesh, TheKidneySampleBecomesOneSoundBodyThatTetrahedralizes) {
    const std::vector<bake::RemeshPart> parts = bake::kidneyAnatomy();
    ASSERT_EQ(parts.size(), 4u);
    const sim::TriMesh& cortex = parts[0].surface;
    // The dent passes through the far side: some medial vertex lies beyond it (self-intersection).
    double leftmost = 0;
    for (const sim::Vec3& x : cortex.positions())
        leftmost = std::min(leftmost, x.x());
    EXPECT_LT(leftmost, -0.031);
    EXPECT_FALSE(cortex.isClosedOriented()); // the hole
    EXPECT_GT(bake::detail::largestHoleDiameter(cortex), 0);
    EXPECT_FALSE(parts[2].surface.isClosedOriented()); // the open ureter
    EXPECT_TRUE(parts[1].surface.isClosedOriented());
    EXPECT_TRUE(parts[3].surface.isClosedOriented());
    const bake::RemeshResult r = bake::voxelRemesh(parts, params(96));
    expectSound(r);
    EXPECT_EQ(r.report.closedHoles, 1u);
    EXPECT_EQ(r.report.openParts, 1u);
    EXPECT_LT(r.report.distanceMaxMm, 3.0 * r.report.voxelSize * 1e3);
    expectTetrahedralizes(r, 0.004, 0.003, 1000);
}

// The hepatocystic anatomy [issue 57 item 4] arrives as bought anatomy does: separate overlapping
// parts, the liver and the ducts open, UVs on every part; the gallbladder with its ducts and
// artery (what the case simulates) becomes one sound body that tetrahedralizes.
TEST(bake_remesh, TheHepatocysticAnatomyIsBoughtLikeAndItsGallbladderPartsMakeOneSoundBody) {
    const std::vector<bake::RemeshPart> parts = bake::hepatocysticAnatomy();
    ASSERT_NO_FATAL_FAILURE(
        expectNamedPartsWithUvs(parts, {"liver", "gallbladder", "cystic_duct", "common_bile_duct", "cystic_artery"}));
    EXPECT_FALSE(parts[0].surface.isClosedOriented()) << "the liver's bare area is missing";
    EXPECT_TRUE(parts[1].surface.isClosedOriented());
    EXPECT_FALSE(parts[2].surface.isClosedOriented()) << "the cystic duct is an open tube";
    EXPECT_FALSE(parts[3].surface.isClosedOriented());
    EXPECT_TRUE(parts[4].surface.isClosedOriented());
    // sizes: a liver lobe 18 cm across, a gallbladder 8.4 cm long, ducts of 2.5 and 4 mm radius
    auto extent = [](const sim::TriMesh& m) {
        sim::Vec3 lo = sim::Vec3::Constant(1e9), hi = -lo;
        for (const sim::Vec3& x : m.positions()) {
            lo = lo.cwiseMin(x);
            hi = hi.cwiseMax(x);
        }
        return std::pair{lo, hi};
    };
    const auto [liverLo, liverHi] = extent(parts[0].surface);
    const auto [gallLo, gallHi] = extent(parts[1].surface);
    EXPECT_NEAR(liverHi.x() - liverLo.x(), 0.18, 0.002);
    EXPECT_NEAR(gallHi.y() - gallLo.y(), 0.084, 0.002);
    EXPECT_GT(gallHi.z(), liverLo.z() + 0.01) << "the gallbladder lies in its bed, overlapping the liver";
    // the neck is narrower than the body: the pear's taper
    double neckHalfWidth = 0, bodyHalfWidth = 0;
    for (const sim::Vec3& x : parts[1].surface.positions()) {
        if (std::abs(x.y() - (-0.04)) < 0.004) neckHalfWidth = std::max(neckHalfWidth, std::abs(x.x()));
        if (std::abs(x.y() - (-0.005)) < 0.004) bodyHalfWidth = std::max(bodyHalfWidth, std::abs(x.x()));
    }
    EXPECT_LT(neckHalfWidth, 0.6 * bodyHalfWidth);
    // the gallbladder, both ducts and the artery: one sound body
    const std::vector<bake::RemeshPart> gall(parts.begin() + 1, parts.end());
    const bake::RemeshResult r = bake::voxelRemesh(gall, params(96));
    expectSound(r);
    EXPECT_EQ(r.report.openParts, 2u) << "the two open ducts";
    expectTetrahedralizes(r, 0.004, 0.003, 1000);
}

// The rectum's anatomy [issue 57 item 5] as bought anatomy: the mesorectum a closed shell that
// overlaps the rectal wall, the rectum, pelvic wall and peritoneum open, UVs on every part; the
// mesorectum alone makes one sound body that tetrahedralizes.
TEST(bake_remesh, TheRectumAnatomyIsBoughtLikeAndItsMesorectumMakesOneSoundBody) {
    const std::vector<bake::RemeshPart> parts = bake::rectumAnatomy();
    ASSERT_NO_FATAL_FAILURE(expectNamedPartsWithUvs(parts, {"mesorectum", "rectum", "pelvic_wall", "peritoneum"}));
    const bool closed[] = {true, false, false, false};
    for (size_t i = 0; i < parts.size(); ++i)
        EXPECT_EQ(parts[i].surface.isClosedOriented(), closed[i]) << parts[i].name;
    // sizes: the fat 124 mm long, its top (the dissection plane) at z 0; the rectal wall's radius
    // 24.6 mm reaches 2 mm into the fat's inner face (22.5 mm)
    sim::Vec3 lo = sim::Vec3::Constant(1e9), hi = -lo;
    double innerMin = 1e9;
    for (const sim::Vec3& x : parts[0].surface.positions()) {
        lo = lo.cwiseMin(x);
        hi = hi.cwiseMax(x);
        innerMin = std::min(innerMin, std::hypot(x.y() - 0.01, x.z() + 0.032));
    }
    EXPECT_NEAR(hi.x() - lo.x(), 0.124, 1e-6);
    EXPECT_NEAR(hi.z(), 0.0, 2e-4);
    EXPECT_NEAR(innerMin, 0.0225, 1e-4);
    double rectumRadius = 0;
    for (const sim::Vec3& x : parts[1].surface.positions())
        rectumRadius = std::max(rectumRadius, std::hypot(x.y() - 0.01, x.z() + 0.032));
    EXPECT_NEAR(rectumRadius, 0.0246, 1e-4);
    const bake::RemeshResult r = bake::voxelRemesh({parts[0]}, params(96));
    expectSound(r);
    EXPECT_EQ(r.report.openParts, 0u);
    expectTetrahedralizes(r, 0.005, 0.005, 1000);
}
