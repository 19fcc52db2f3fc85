// Light-sample painting data [A §6.3.2]: brush and fill operations replayed on a body's surface at
// rest, the per-node classes a case carries (.vsamples), and how the player puts them on the body
// and on the fascia cut from it.
#include "render/sample_map.hpp"
#include "render/scene_view.hpp"
#include "sim/mesh/generators.hpp"
#include "sim/scene/world.hpp"
#include "sim/util/error.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>

using namespace viscera::render;
namespace sim = viscera::sim;

namespace {

std::unique_ptr<sim::TetMesh> slab() {
    sim::BoxSpec spec;
    spec.size = sim::Vec3(0.08, 0.02, 0.04);
    spec.cells = {16, 4, 8};
    return sim::makeBoxTetMesh(spec);
}

/// One XPBD body "slab" fixed at node 0.
sim::SceneDesc slabScene() {
    sim::SceneDesc scene;
    scene.xpbd.substeps = 20;
    sim::BodyDesc b;
    b.name = "slab";
    b.meshPath = "meshes/slab.vtet";
    b.fixedNodes = {0};
    scene.bodies.push_back(b);
    return scene;
}

Eigen::Vector3d restOf(const RenderMesh& m, size_t v) {
    return {m.rest[3 * v], m.rest[3 * v + 1], m.rest[3 * v + 2]};
}

std::string errorOf(const std::string& text, size_t nodes) {
    try {
        parseSampleMap(text, "liver.vsamples", nodes);
    } catch (const viscera::InputError& e) {
        return e.what();
    }
    return "no error";
}

} // namespace

TEST(SamplePaint, BodySurfaceMeshIsWhatTheSceneViewDrawsForTheBody) {
    auto mesh = slab();
    const RenderMesh surface = bodySurfaceMesh(*mesh, "slab", 0);
    const sim::SceneDesc scene = slabScene();
    std::vector<std::unique_ptr<sim::TetMesh>> meshes;
    meshes.push_back(mesh->clone());
    auto world = sim::World::assemble(scene, std::move(meshes), {}, {"gravity", "xpbd"}, "test");
    const SceneView view = SceneView::fromWorld(*world);
    const RenderMesh& drawn = view.meshes()[0];
    EXPECT_EQ(surface.indices, drawn.indices);
    EXPECT_EQ(surface.rest, drawn.rest);
    EXPECT_EQ(surface.sourceVertex, drawn.sourceVertex);
    EXPECT_EQ(surface.source, RenderMesh::Source::Body);
}

TEST(SamplePaint, BrushSetsExactlyTheVerticesWithinItsRadiusOfADab) {
    auto mesh = slab();
    RenderMesh m = bodySurfaceMesh(*mesh, "slab");
    const std::vector<Eigen::Vector3d> dabs = {{0.02, 0.0, 0.02}, {0.03, 0.0, 0.025}};
    const double r = 0.008;
    const size_t set = paintSampleBrush(m, dabs, r, 8);
    size_t expected = 0;
    for (size_t v = 0; v < m.vertexCount(); ++v) {
        bool inside = false;
        for (const auto& c : dabs)
            inside |= (restOf(m, v) - c).norm() <= r;
        expected += inside;
        EXPECT_EQ(m.sampleMap[v], inside ? 8.0f : 0.0f) << "vertex " << v;
    }
    EXPECT_EQ(set, expected);
    EXPECT_GT(set, 4u);
    EXPECT_THROW(paintSampleBrush(m, dabs, r, 2), std::invalid_argument);
}

TEST(SamplePaint, ReplayKeepsThePaintedAreaAndAppliesOperationsInOrder) {
    auto mesh = slab(); // 5 mm cells: a vertex owns 25 mm² of a side
    RenderMesh m = bodySurfaceMesh(*mesh, "slab");
    SamplePaintOp fill; // the y = 0 side of the slab: a 90° edge stops a 30° fill
    fill.tool = SamplePaintOp::Tool::Fill;
    fill.samples = 4;
    fill.points = {{0.04, -0.001, 0.02}};
    fill.maxAngleDeg = 30;
    SamplePaintOp brush; // a disc of radius 8 mm inside that side
    brush.samples = 8;
    brush.points = {{0.04, 0.0, 0.02}};
    brush.radius = 0.008;
    applySamplePaint(m, {fill, brush});
    const double h = 0.005, cellArea = h * h, disc = M_PI * brush.radius * brush.radius, side = 0.08 * 0.04;
    for (size_t v = 0; v < m.vertexCount(); ++v) {
        const Eigen::Vector3d p = restOf(m, v);
        const double d = (p - brush.points[0]).norm();
        const bool onSide = std::abs(p.y()) < 1e-6;
        const bool sideInterior = onSide && p.x() > 1e-6 && p.x() < 0.08 - 1e-6 && p.z() > 1e-6 && p.z() < 0.04 - 1e-6;
        if (d <= brush.radius - h)
            EXPECT_EQ(m.sampleMap[v], 8.0f) << "vertex " << v << " deep in the disc";
        else if (sideInterior && d >= brush.radius + h)
            EXPECT_EQ(m.sampleMap[v], 4.0f) << "vertex " << v << " on the side, off the disc";
        else if (!onSide && std::abs(p.y()) > h + 1e-6)
            EXPECT_EQ(m.sampleMap[v], 0.0f) << "vertex " << v << " off the side";
    }
    // each class keeps its painted area to within a cell (the disc: 201 mm², 8 cells)
    const auto area = sampleClassAreas(m);
    EXPECT_NEAR(area[3], disc, 0.6 * cellArea);
    EXPECT_NEAR(area[2], side - disc, 1.2 * cellArea);
    EXPECT_NEAR(area[1], 0.0, 1e-12);
    // the other order: the fill paints over the whole disc
    applySamplePaint(m, {brush, fill});
    for (float c : m.sampleMap)
        EXPECT_NE(c, 8.0f);
    EXPECT_NEAR(sampleClassAreas(m)[2], side, 0.6 * cellArea);
    applySamplePaint(m, {fill, brush});
    // a bad operation: named, and the map stays as it was
    const auto before = m.sampleMap;
    SamplePaintOp bad = brush;
    bad.radius = -1;
    try {
        applySamplePaint(m, {fill, bad});
        FAIL() << "no error";
    } catch (const std::invalid_argument& e) {
        EXPECT_STREQ(e.what(), "render::applySamplePaint(): mesh slab: operation 1: radius must be finite and > 0, "
                               "got -1");
    }
    bad = fill;
    bad.points.push_back({0, 0, 0});
    EXPECT_THROW(applySamplePaint(m, {bad}), std::invalid_argument);
    bad = fill;
    bad.maxAngleDeg = 200;
    EXPECT_THROW(applySamplePaint(m, {bad}), std::invalid_argument);
    bad = brush;
    bad.points = {{NAN, 0, 0}};
    EXPECT_THROW(applySamplePaint(m, {bad}), std::invalid_argument);
    EXPECT_EQ(m.sampleMap, before);
}

TEST(SamplePaint, NearestFaceIsTheTriangleClosestToThePoint) {
    auto mesh = slab();
    const RenderMesh m = bodySurfaceMesh(*mesh, "slab");
    const Eigen::Vector3d p(0.0412, 0.0105 + 0.02, 0.0213); // above the y = 0.02 side
    const size_t f = nearestFace(m, p);
    for (int k = 0; k < 3; ++k)
        EXPECT_NEAR(restOf(m, m.indices[3 * f + k]).y(), 0.02, 1e-7);
    RenderMesh empty;
    EXPECT_THROW(nearestFace(empty, p), std::invalid_argument);
}

TEST(SamplePaint, NodeClassesRoundTripThroughTheCaseFormat) {
    auto mesh = slab();
    RenderMesh m = bodySurfaceMesh(*mesh, "slab");
    paintSampleBrush(m, {{0.0, 0.0, 0.0}}, 0.01, 8);
    paintSampleBrush(m, {{0.08, 0.02, 0.04}}, 0.01, 1);
    const std::vector<uint8_t> nodes = nodeSampleClasses(m, mesh->vertexCount());
    ASSERT_EQ(nodes.size(), mesh->vertexCount());
    size_t interior = 0;
    for (size_t v = 0; v < m.vertexCount(); ++v)
        EXPECT_EQ(nodes[m.sourceVertex[v]], static_cast<uint8_t>(m.sampleMap[v]));
    for (size_t n = 0; n < nodes.size(); ++n)
        interior += std::find(m.sourceVertex.begin(), m.sourceVertex.end(), int32_t(n)) == m.sourceVertex.end();
    EXPECT_GT(interior, 0u); // interior nodes exist and carry 0
    const std::string text = formatSampleMap(nodes);
    const std::string header = "vsamples 1\nnodes " + std::to_string(nodes.size()) + "\n";
    EXPECT_EQ(text.substr(0, header.size()), header);
    EXPECT_EQ(text.size(), header.size() + 2 * nodes.size()); // one digit and a newline per node
    EXPECT_EQ(parseSampleMap(text, "slab.vsamples", nodes.size()), nodes);
    EXPECT_THROW(formatSampleMap({}), std::invalid_argument);
    EXPECT_THROW(formatSampleMap({0, 3}), std::invalid_argument);
}

TEST(SamplePaint, MalformedSampleMapsAreRefusedNamingTheLineAndRule) {
    EXPECT_EQ(errorOf("vsamples 1\nnodes 2\n0\n3\n", 2),
              "liver.vsamples: line 4: class of node 1 is 3 (must be 0, 1, 4 or 8)");
    EXPECT_EQ(errorOf("vsamples 2\nnodes 1\n0\n", 1),
              "liver.vsamples: line 1: unsupported vsamples version 2 (supported: 1)");
    EXPECT_EQ(errorOf("vweights 1\nnodes 1\n1\n", 1), "liver.vsamples: line 1: header must be 'vsamples <version>'");
    EXPECT_EQ(errorOf("vsamples 1\nnodes 3\n0\n1\n4\n", 2), "liver.vsamples: line 2: file has 3 nodes, the mesh has 2");
    EXPECT_EQ(errorOf("vsamples 1\nnodes 2\n8\n", 2),
              "liver.vsamples: unexpected end of file (expected class of node 1 (file declares 2 nodes))");
    EXPECT_EQ(errorOf("vsamples 1\nnodes 1\n8\n1\n", 1),
              "liver.vsamples: line 4: unexpected content after the last class (file declares 1 nodes)");
    EXPECT_EQ(errorOf("vsamples 1\nnodes 1\n8 8\n", 1),
              "liver.vsamples: line 3: class of node 0: expected one value per line, found 2");
    EXPECT_EQ(errorOf("vsamples 1\nnodes 1\nx\n", 1),
              "liver.vsamples: line 3: class of node 0 'x' is not a valid number");
    EXPECT_EQ(errorOf("# painted\nvsamples 1\nnodes 1\n4 # near the light\n", 1), "no error");
}

TEST(SamplePaint, PlayerPutsNodeClassesOnTheBodyAndOnTheFasciaCutFromIt) {
    sim::SceneDesc scene = slabScene();
    sim::SurfaceDesc s;
    s.name = "fascia";
    s.meshPath = "meshes/fascia.vtri";
    s.attachTo = "slab";
    scene.surfaces.push_back(s);
    auto mesh = slab();
    RenderMesh painted = bodySurfaceMesh(*mesh, "slab");
    paintSampleBrush(painted, {{0.04, 0.02, 0.04}}, 0.012, 8);
    const std::vector<uint8_t> nodes = nodeSampleClasses(painted, mesh->vertexCount());
    // the fascia: the boundary triangles on top (z = 0.04), with their own vertices
    mesh->requireLevel(3);
    const sim::TriMesh& boundary = mesh->boundary();
    std::vector<sim::Vec3> pos;
    std::vector<sim::Tri> tris;
    std::map<int32_t, int32_t> local;
    for (const sim::Tri& t : boundary.triangles()) {
        bool top = true;
        for (int k = 0; k < 3; ++k)
            top &= std::abs(boundary.positions()[t[k]].z() - 0.04) < 1e-12;
        if (!top) continue;
        sim::Tri lt;
        for (int k = 0; k < 3; ++k) {
            auto [it, fresh] = local.emplace(t[k], int32_t(pos.size()));
            if (fresh) pos.push_back(boundary.positions()[t[k]]);
            lt[k] = it->second;
        }
        tris.push_back(lt);
    }
    std::vector<std::unique_ptr<sim::TetMesh>> meshes;
    meshes.push_back(mesh->clone());
    std::vector<sim::TriMesh> surfaces;
    surfaces.push_back(sim::TriMesh::fromArrays(pos, tris));
    auto world =
        sim::World::assemble(scene, std::move(meshes), std::move(surfaces), {"fascia", "gravity", "xpbd"}, "test");
    SceneView view = SceneView::fromWorld(*world);
    ASSERT_EQ(view.meshes().size(), 2u);
    applyNodeSampleClasses(view, 0, nodes, {0}, 1e-6f);
    const RenderMesh& body = view.meshes()[0];
    const RenderMesh& fascia = view.meshes()[1];
    EXPECT_EQ(body.sampleMap, painted.sampleMap);
    size_t eight = 0;
    for (size_t v = 0; v < fascia.vertexCount(); ++v) {
        const Eigen::Vector3d p = restOf(fascia, v);
        const float want = (p - Eigen::Vector3d(0.04, 0.02, 0.04)).norm() <= 0.012 ? 8.0f : 0.0f;
        EXPECT_EQ(fascia.sampleMap[v], want) << "fascia vertex " << v;
        eight += want == 8.0f;
    }
    EXPECT_GT(eight, 3u);
    // the map must match the body's nodes
    EXPECT_THROW(applyNodeSampleClasses(view, 0, std::vector<uint8_t>(3, 0), {0}, 1e-6f), std::invalid_argument);
    std::vector<uint8_t> bad = nodes;
    bad[body.sourceVertex[0]] = 5;
    EXPECT_THROW(applyNodeSampleClasses(view, 0, bad, {0}, 1e-6f), std::invalid_argument);
}
