// Renderer data without GL: PNG round trip, image comparison, thickness bake by ray casting
// [A §6.3.1], SceneView built from and updated by a simulated World.
#include "render/image.hpp"
#include "render/sample_map.hpp"
#include "render/scene_view.hpp"
#include "render/thickness_bake.hpp"
#include "sim/mesh/generators.hpp"
#include "sim/scene/world.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

using namespace viscera::render;
namespace sim = viscera::sim;

TEST(Png, RoundTripIsExact) {
    Image img;
    img.width = 37;
    img.height = 11;
    img.rgba.resize(size_t(img.width) * img.height * 4);
    for (size_t i = 0; i < img.rgba.size(); ++i)
        img.rgba[i] = uint8_t((i * 7919u) >> 3);
    const auto path = std::filesystem::path(VISCERA_BINARY_DIR) / "test_render_roundtrip.png";
    writePng(path, img);
    const Image back = readPng(path);
    EXPECT_EQ(back.width, 37);
    EXPECT_EQ(back.height, 11);
    EXPECT_EQ(back.rgba, img.rgba);
    std::filesystem::remove(path);
    EXPECT_THROW(readPng(path), std::runtime_error);
    // A folder that cannot exist (its parent is a file): refused, and nothing is left behind.
    const auto file = std::filesystem::path(VISCERA_BINARY_DIR) / "test_render_not_a_folder";
    std::ofstream(file) << "x";
    EXPECT_THROW(writePng(file / "x.png", img), std::runtime_error);
    std::filesystem::remove(file);
}

TEST(Image, CompareReportsRmseMaxAndMask) {
    Image a, b;
    a.width = b.width = 2;
    a.height = b.height = 1;
    a.rgba = {10, 10, 10, 255, 0, 0, 0, 255};
    b.rgba = {10, 10, 10, 0, 6, 0, 0, 255}; // alpha ignored; one channel off by 6
    const ImageDifference d = compareImages(a, b);
    EXPECT_EQ(d.pixels, 2u);
    EXPECT_EQ(d.differing, 1u);
    EXPECT_EQ(d.maxChannel, 6);
    EXPECT_NEAR(d.rmse, std::sqrt(36.0 / 6.0), 1e-12);
    EXPECT_EQ(compareImages(a, b, {1, 0}).differing, 0u);
    Image c = a;
    c.width = 1;
    EXPECT_THROW(compareImages(a, c), std::invalid_argument);
}

TEST(ThicknessBake, SphereAndEllipsoidByRayCasting) {
    // Sphere of radius R: a chord at angle θ from the inward normal is 2R cos θ.
    const double R = 0.02;
    const sim::TriMesh sphere = sim::makeEllipsoidSurface(sim::Vec3::Zero(), sim::Vec3(R, R, R), 48, 24);
    std::vector<Eigen::Vector3f> pos, nrm;
    std::vector<std::array<uint32_t, 3>> tris;
    for (const auto& p : sphere.positions()) {
        pos.push_back(p.cast<float>());
        nrm.push_back(p.normalized().cast<float>());
    }
    for (const auto& t : sphere.triangles())
        tris.push_back({uint32_t(t[0]), uint32_t(t[1]), uint32_t(t[2])});
    const TriangleBvh bvh(pos, tris);
    EXPECT_NEAR(bvh.raycast(Eigen::Vector3f(0, 0, -1), Eigen::Vector3f(0, 0, 1), 0.0f, 10.0f), 1.0f - R, 2e-4f);
    EXPECT_LT(bvh.raycast(Eigen::Vector3f(0, 0, -1), Eigen::Vector3f(0, 1, 0), 0.0f, 10.0f), 0.0f); // miss
    const auto t = bakeThickness(pos, nrm, bvh);
    double mean = 0;
    for (float v : t) {
        EXPECT_GT(v, 1.5f * R);
        EXPECT_LT(v, 2.0f * R + 1e-4f);
        mean += v / t.size();
    }
    // A sphere of half the radius through SceneView::addMesh: half the thickness.
    SceneView view;
    view.addMesh("small", sim::makeEllipsoidSurface(sim::Vec3::Zero(), sim::Vec3(R / 2, R / 2, R / 2), 48, 24),
                 view.addMaterial(TissueMaterial{}));
    double smallMean = 0;
    for (float v : view.meshes()[0].thickness)
        smallMean += v / view.meshes()[0].thickness.size();
    EXPECT_NEAR(smallMean / mean, 0.5, 0.02);
    // Rays that leave an open surface count as the maximum thickness.
    view.addMesh("sheet", sim::makeBoxSurface(sim::Vec3(0, 0, 0), sim::Vec3(0.01, 0.01, 0.01)), 0);
    EXPECT_FALSE(view.meshes()[1].doubleSided);
    EXPECT_THROW(TriangleBvh(pos, {{0, 1, 99999}}), std::invalid_argument);
}

TEST(ThicknessBake, TextureOfASphereMatchesTheChordsOfItsRayCone) {
    // [A §6.3.1] baked per texel: every texel of a UV sphere of radius R holds the mean chord
    // 2R cos θ over the bake's cone of rays, whatever point of the surface it lies on
    const float R = 0.02f;
    SceneView view;
    view.addMesh("ball", sim::makeEllipsoidSurface(sim::Vec3::Zero(), sim::Vec3(R, R, R), 64, 32),
                 view.addMaterial(TissueMaterial{}));
    RenderMesh& m = view.meshes()[0];
    EXPECT_THROW(view.bakeThicknessMap(0, 64), std::invalid_argument) << "no UVs yet";
    m.uv.resize(2 * m.vertexCount());
    for (size_t v = 0; v < m.vertexCount(); ++v) { // longitude, latitude
        const float x = m.rest[3 * v], y = m.rest[3 * v + 1], z = m.rest[3 * v + 2];
        m.uv[2 * v] = 0.5f + std::atan2(y, x) / (2.0f * float(M_PI));
        m.uv[2 * v + 1] = 1.0f - std::acos(std::clamp(z / R, -1.0f, 1.0f)) / float(M_PI);
    }
    const uint64_t revision = m.staticRevision;
    const int size = 128;
    const size_t covered = view.bakeThicknessMap(0, size);
    EXPECT_GT(m.staticRevision, revision);
    ASSERT_EQ(m.thicknessMap.width, size);
    EXPECT_GT(covered, size_t(size * size * 0.85)) << "all but the seam column";
    const ThicknessBakeSettings bake;
    double coneMean = 0; // the bake's ray pattern: cos θ = sqrt(1 − 0.36 u)
    for (int r = 0; r < bake.rays; ++r)
        coneMean += std::sqrt(1.0 - 0.36 * (r + 0.5) / bake.rays) / bake.rays;
    const double expected = 2.0 * R * coneMean;
    double sumErr = 0, maxErr = 0;
    size_t n = 0;
    for (size_t i = 0; i < size_t(size) * size; ++i) {
        const double t = m.thicknessMap.rgba[4 * i] / 255.0 * kThicknessMapRange;
        if (t == 0) continue; // not covered
        sumErr += std::abs(t - expected);
        maxErr = std::max(maxErr, std::abs(t - expected));
        ++n;
    }
    ASSERT_GT(n, size_t(size * size * 0.9));
    std::printf("thickness map of a sphere (R %.0f mm, %d^2 texels): expected %.3f mm, mean |error| %.3f mm, max "
                "%.3f mm (8-bit step %.3f mm)\n",
                1e3 * R, size, 1e3 * expected, 1e3 * sumErr / n, 1e3 * maxErr, 1e3 * kThicknessMapRange / 255);
    EXPECT_LT(sumErr / n, 0.02 * expected);
    EXPECT_LT(maxErr, 0.08 * expected);
    // bad input
    std::vector<Eigen::Vector3f> p(3, Eigen::Vector3f::Zero());
    const TriangleBvh bvh({Eigen::Vector3f(0, 0, 0), Eigen::Vector3f(1, 0, 0), Eigen::Vector3f(0, 1, 0)}, {{0, 1, 2}});
    EXPECT_THROW(bakeThicknessTexture(p, p, {{0, 1, 2}}, {}, bvh, 8, 0.05f), std::invalid_argument);
    const std::vector<Eigen::Vector2f> uv(3, Eigen::Vector2f::Zero());
    EXPECT_THROW(bakeThicknessTexture(p, p, {{0, 1, 3}}, uv, bvh, 8, 0.05f), std::invalid_argument);
    EXPECT_THROW(bakeThicknessTexture(p, p, {{0, 1, 2}}, uv, bvh, 0, 0.05f), std::invalid_argument);
    EXPECT_THROW(bakeThicknessTexture(p, p, {{0, 1, 2}}, uv, bvh, 8, 0.0f), std::invalid_argument);
}

TEST(SceneView, FollowsTheWorldWithoutReallocating) {
    sim::SceneDesc scene;
    scene.xpbd.substeps = 20;
    sim::BodyDesc b;
    b.name = "organ";
    b.meshPath = "meshes/organ.vtet";
    b.fixedNodes = {0, 1, 2};
    scene.bodies.push_back(b);
    std::vector<std::unique_ptr<sim::TetMesh>> meshes;
    meshes.push_back(sim::makeBoxTetMesh({}));
    auto world = sim::World::assemble(scene, std::move(meshes), {}, {"gravity", "xpbd"}, "test");
    SceneView view = SceneView::fromWorld(*world);
    ASSERT_EQ(view.meshes().size(), 1u);
    const RenderMesh& m = view.meshes()[0];
    EXPECT_EQ(m.name, "organ");
    EXPECT_EQ(view.materials()[m.material].name, "organ");
    auto rest = world->restMesh(0).clone();
    rest->requireLevel(3);
    EXPECT_EQ(m.vertexCount(), rest->boundary().vertexCount());
    EXPECT_EQ(m.triangleCount(), rest->boundary().triangleCount());
    for (float t : m.thickness) {
        EXPECT_GT(t, 0.0f);
        EXPECT_LE(t, 0.05f);
    }
    const float* before = m.positions.data();
    const uint64_t revision = m.revision;
    for (int f = 0; f < 3; ++f)
        world->step();
    view.updateFromWorld(*world);
    EXPECT_EQ(m.positions.data(), before); // same storage
    EXPECT_GT(m.revision, revision);
    for (size_t v = 0; v < m.vertexCount(); ++v) {
        const sim::Vec3& p = world->positions(0)[m.sourceVertex[v]];
        ASSERT_FLOAT_EQ(m.positions[3 * v + 2], float(p.z()));
    }
    EXPECT_THROW(view.setHeat(0, {1.0f}), std::invalid_argument);
    // the overlay: 4 values per vertex or none, clamped, non-finite dropped; a static change
    EXPECT_THROW(view.setOverlay(0, {1.0f, 0.0f, 0.0f}), std::invalid_argument);
    const uint64_t statics = m.staticRevision;
    std::vector<float> rgba(4 * m.vertexCount(), 2.0f);
    rgba[1] = NAN;
    rgba[2] = -1.0f;
    view.setOverlay(0, rgba);
    EXPECT_EQ(m.overlay[0], 1.0f);
    EXPECT_EQ(m.overlay[1], 0.0f);
    EXPECT_EQ(m.overlay[2], 0.0f);
    EXPECT_GT(m.staticRevision, statics);
    view.setOverlay(0, {});
    EXPECT_TRUE(m.overlay.empty());
}

TEST(SampleMap, ConnectedFillStopsAtSharpEdgesAndUvBordersAndAreasAddUp) {
    SceneView view;
    const uint32_t material = view.addMaterial(TissueMaterial{});
    const size_t i =
        view.addMesh("box", sim::makeBoxSurface(sim::Vec3(0, 0, 0), sim::Vec3(0.04, 0.02, 0.01)), material);
    RenderMesh& m = view.meshes()[i];
    auto normal = [&](size_t f) {
        auto p = [&](int k) {
            const uint32_t v = m.indices[3 * f + k];
            return Eigen::Vector3d(m.rest[3 * v], m.rest[3 * v + 1], m.rest[3 * v + 2]);
        };
        return Eigen::Vector3d((p(1) - p(0)).cross(p(2) - p(0)).normalized());
    };
    const double total = 2 * (0.04 * 0.02 + 0.04 * 0.01 + 0.02 * 0.01);
    const auto none = sampleClassAreas(m);
    EXPECT_NEAR(none[0], total, 1e-6 * total); // rest positions are floats
    // a 40° fill from face 0 reaches exactly the faces of its side (the box's edges are 90°)
    const uint64_t statics = m.staticRevision;
    const size_t reached = fillSampleClass(m, 0, 8, 40.0f);
    size_t sameSide = 0;
    for (size_t f = 0; f < m.triangleCount(); ++f)
        sameSide += normal(f).dot(normal(0)) > 0.999;
    EXPECT_EQ(reached, sameSide);
    EXPECT_GT(m.staticRevision, statics);
    for (size_t f = 0; f < m.triangleCount(); ++f) {
        const bool onSide = normal(f).dot(normal(0)) > 0.999;
        for (int k = 0; k < 3 && onSide; ++k)
            EXPECT_EQ(m.sampleMap[m.indices[3 * f + k]], 8.0f);
    }
    auto areas = sampleClassAreas(m);
    EXPECT_NEAR(areas[0] + areas[1] + areas[2] + areas[3], total, 1e-6 * total); // rest positions are floats
    EXPECT_GT(areas[3], 0.0);
    // 180°: everything; then erase with 0
    EXPECT_EQ(fillSampleClass(m, 0, 4, 180.0f), m.triangleCount());
    EXPECT_NEAR(sampleClassAreas(m)[2], total, 1e-6 * total); // rest positions are floats
    // a UV border: two islands split by x; the fill stays in the seed's island
    std::vector<int32_t> island(m.triangleCount());
    for (size_t f = 0; f < m.triangleCount(); ++f) {
        double cx = 0;
        for (int k = 0; k < 3; ++k)
            cx += m.rest[3 * m.indices[3 * f + k]];
        island[f] = cx / 3 < 0.02 ? 0 : 1;
    }
    const size_t seedIsland0 = std::find(island.begin(), island.end(), 0) - island.begin();
    const size_t inIsland = fillSampleClass(m, seedIsland0, 1, 180.0f, island);
    EXPECT_EQ(inIsland, static_cast<size_t>(std::count(island.begin(), island.end(), 0)));
    // bad input: named, nothing changed
    const auto before = m.sampleMap;
    EXPECT_THROW(fillSampleClass(m, 0, 3, 40.0f), std::invalid_argument);
    EXPECT_THROW(fillSampleClass(m, m.triangleCount(), 8, 40.0f), std::invalid_argument);
    EXPECT_THROW(fillSampleClass(m, 0, 8, NAN), std::invalid_argument);
    EXPECT_THROW(fillSampleClass(m, 0, 8, 40.0f, {1, 2}), std::invalid_argument);
    EXPECT_EQ(m.sampleMap, before);
}
