// Face mask for dissection [A §5.3.1]: cut faces are dropped by rewriting the compacted index list
// into the existing index buffer; nothing is reallocated and the vertex count never changes.
#include "render/renderer.hpp"
#include "sim/mesh/generators.hpp"
#include "sim/scene/interaction_rig.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

using namespace viscera::render;
using ::testing::HasSubstr;

TEST(FaceMask, CutFacesAreDroppedWithoutReallocation) {
    SceneView view;
    view.addMaterial(defaultMaterialFor("liver"));
    const auto box = viscera::sim::makeBoxSurface(viscera::sim::Vec3(0, 0, 0), viscera::sim::Vec3(1, 1, 1));
    view.addMesh("box", box, 0);
    auto mock = std::make_unique<MockBackend>();
    MockBackend* m = mock.get();
    Renderer r(std::move(mock), RenderSettings{});
    r.renderFrame(view);
    const uint64_t allocations = m->stats().bufferAllocations;
    const RenderMesh& mesh = view.meshes()[0];
    ASSERT_EQ(mesh.triangleCount(), 12u);
    EXPECT_EQ(m->meshes()[0].drawnTriangles, 12u);

    // Drop faces 1, 4 and 11.
    std::vector<uint8_t> mask(12, 1);
    mask[1] = mask[4] = mask[11] = 0;
    view.setFaceMask(0, mask);
    EXPECT_EQ(mesh.drawnTriangleCount(), 9u);
    r.renderFrame(view);
    EXPECT_EQ(m->stats().bufferAllocations, allocations);
    EXPECT_EQ(m->meshes()[0].maskUpdates, 1u);
    EXPECT_EQ(m->meshes()[0].drawnTriangles, 9u);
    EXPECT_EQ(m->meshes()[0].vertices, mesh.vertexCount());
    // The compacted list keeps the other faces, in order, with their vertex indices.
    std::vector<uint32_t> expect;
    for (size_t f = 0; f < 12; ++f)
        if (mask[f])
            for (int c = 0; c < 3; ++c)
                expect.push_back(mesh.indices[3 * f + c]);
    EXPECT_EQ(m->meshes()[0].drawnIndices, expect);

    // The same mask again: no upload. A cleared mask draws every face again.
    view.setFaceMask(0, mask);
    r.renderFrame(view);
    EXPECT_EQ(m->meshes()[0].maskUpdates, 1u);
    view.setFaceMask(0, {});
    r.renderFrame(view);
    EXPECT_EQ(m->meshes()[0].maskUpdates, 2u);
    EXPECT_EQ(m->meshes()[0].drawnIndices, mesh.indices);
    // Everything cut: nothing drawn, still no reallocation.
    view.setFaceMask(0, std::vector<uint8_t>(12, 0));
    r.renderFrame(view);
    EXPECT_EQ(m->meshes()[0].drawnTriangles, 0u);
    EXPECT_EQ(m->stats().bufferAllocations, allocations);
    EXPECT_TRUE(r.warnings().empty());
}

TEST(FaceMask, AMaskSetBeforeTheFirstFrameIsUploadedWithTheMesh) {
    SceneView view;
    view.addMaterial(defaultMaterialFor("liver"));
    view.addMesh("box", viscera::sim::makeBoxSurface(viscera::sim::Vec3(0, 0, 0), viscera::sim::Vec3(1, 1, 1)), 0);
    std::vector<uint8_t> mask(12, 0);
    mask[3] = 1;
    view.setFaceMask(0, mask);
    auto mock = std::make_unique<MockBackend>();
    MockBackend* m = mock.get();
    Renderer r(std::move(mock), RenderSettings{});
    r.renderFrame(view);
    EXPECT_EQ(m->meshes()[0].drawnTriangles, 1u);
}

TEST(FaceMask, WrongSizeNamesTheMesh) {
    SceneView view;
    view.addMaterial(defaultMaterialFor("liver"));
    view.addMesh("box", viscera::sim::makeBoxSurface(viscera::sim::Vec3(0, 0, 0), viscera::sim::Vec3(1, 1, 1)), 0);
    try {
        view.setFaceMask(0, std::vector<uint8_t>(5, 1));
        FAIL();
    } catch (const std::invalid_argument& e) {
        EXPECT_THAT(e.what(), HasSubstr("render::SceneView::setFaceMask(): mesh box has 12 triangles, got 5 flags"));
    }
}

// The World's dissection reaches the renderer: SceneView::updateFromWorld applies the cut faces of
// the fascia as its face mask (same triangle order as the simulated surface).
TEST(FaceMask, UpdateFromWorldDropsTheFasciaFacesTheHookCut) {
    using namespace viscera::sim;
    std::unique_ptr<World> w = test::assemble(test::makeRig());
    SceneView view = SceneView::fromWorld(*w);
    size_t fascia = view.meshes().size();
    for (size_t i = 0; i < view.meshes().size(); ++i)
        if (view.meshes()[i].name == "fascia") fascia = i;
    ASSERT_LT(fascia, view.meshes().size());
    const size_t all = view.meshes()[fascia].triangleCount();
    EXPECT_EQ(view.meshes()[fascia].drawnTriangleCount(), all);
    for (int f = 0; f < 20; ++f)
        w->step();
    view.updateFromWorld(*w);
    const int cut = w->interaction()->summary().fasciaTrianglesCut;
    ASSERT_GT(cut, 0);
    EXPECT_EQ(view.meshes()[fascia].drawnTriangleCount(), all - size_t(cut));
    for (const RenderMesh& m : view.meshes())
        if (m.name != "fascia") {
            EXPECT_EQ(m.drawnTriangleCount(), m.triangleCount()) << m.name;
        }
}

// The cut surface of a tet body [A §5.3.1]: cutting a tet drops the body's boundary faces it
// owned and shows its intact neighbours' faces towards it, in a mesh of fixed size.
namespace {

struct CutBody {
    std::unique_ptr<viscera::sim::TetMesh> rest;
    SceneView view;
    size_t body = 0, cut = 0;
    explicit CutBody(size_t capacity = SceneView::kCutFaceCapacity) {
        viscera::sim::BoxSpec spec;
        spec.size = viscera::sim::Vec3(0.04, 0.03, 0.02);
        spec.cells = {4, 3, 2};
        rest = viscera::sim::makeBoxTetMesh(spec);
        rest->requireLevel(3);
        view.addMaterial(defaultMaterialFor("fat"));
        view.meshes().push_back(bodySurfaceMesh(*rest, "fat", 0));
        cut = view.addBodyCut(body, *rest, capacity);
    }
    /// A tet none of whose faces is on the boundary.
    size_t interiorTet() const {
        for (size_t t = 0; t < rest->tetCount(); ++t) {
            bool inside = true;
            for (int i = 0; i < 4; ++i)
                inside &= rest->opp(int32_t(4 * t + i)) != viscera::sim::kNone;
            if (inside) return t;
        }
        return rest->tetCount();
    }
    Eigen::Vector3d centroid(size_t t) const {
        Eigen::Vector3d c = Eigen::Vector3d::Zero();
        for (int32_t v : rest->tets()[t])
            c += rest->positions()[size_t(v)];
        return c / 4;
    }
};

} // namespace

TEST(BodyCut, ACutTetShowsItsNeighboursFacesTowardsTheCavity) {
    CutBody b;
    const RenderMesh& cutMesh = b.view.meshes()[b.cut];
    const RenderMesh& body = b.view.meshes()[b.body];
    EXPECT_FALSE(cutMesh.visible) << "nothing cut yet";
    EXPECT_EQ(cutMesh.drawnTriangleCount(), 0u);
    EXPECT_EQ(cutMesh.triangleCount(), SceneView::kCutFaceCapacity);

    const size_t t = b.interiorTet();
    ASSERT_LT(t, b.rest->tetCount());
    std::vector<uint8_t> mask(b.rest->tetCount(), 1);
    mask[t] = 0;
    b.view.setBodyCut(0, mask);
    EXPECT_EQ(b.view.exposedCutFaces(0), 4u);
    EXPECT_TRUE(cutMesh.visible);
    EXPECT_EQ(cutMesh.drawnTriangleCount(), 4u);
    EXPECT_EQ(body.drawnTriangleCount(), body.triangleCount()) << "an interior tet owns no boundary face";
    // Each exposed face faces into the cavity: its normal points to the cut tet's centroid.
    const Eigen::Vector3d c = b.centroid(t);
    for (size_t f = 0; f < 4; ++f) {
        Eigen::Vector3d p[3];
        for (int j = 0; j < 3; ++j)
            p[j] = Eigen::Vector3d(cutMesh.rest[9 * f + 3 * j], cutMesh.rest[9 * f + 3 * j + 1],
                                   cutMesh.rest[9 * f + 3 * j + 2]);
        const Eigen::Vector3d n = (p[1] - p[0]).cross(p[2] - p[0]);
        EXPECT_GT(n.dot(c - (p[0] + p[1] + p[2]) / 3), 0.0) << "face " << f;
    }
    // The same mask again changes nothing; a mask of the wrong size is ignored.
    const uint64_t rev = cutMesh.faceMaskRevision, staticRev = cutMesh.staticRevision;
    b.view.setBodyCut(0, mask);
    b.view.setBodyCut(0, std::vector<uint8_t>(3, 0));
    EXPECT_EQ(cutMesh.faceMaskRevision, rev);
    EXPECT_EQ(cutMesh.staticRevision, staticRev) << "the slots were not refilled";
    EXPECT_EQ(b.view.exposedCutFaces(0), 4u);
    // Healed (a reset): nothing exposed, the cut mesh hidden again.
    b.view.setBodyCut(0, std::vector<uint8_t>(b.rest->tetCount(), 1));
    EXPECT_EQ(cutMesh.drawnTriangleCount(), 0u);
    EXPECT_FALSE(cutMesh.visible);
}

TEST(BodyCut, ABoundaryTetTakesItsOuterFacesAlongAndEverythingCutShowsNothing) {
    CutBody b;
    const RenderMesh& body = b.view.meshes()[b.body];
    const RenderMesh& cutMesh = b.view.meshes()[b.cut];
    const std::vector<int32_t>& bhf = b.rest->boundaryHalfFacets();
    const size_t t = size_t(viscera::sim::TetMesh::cellOf(bhf[0]));
    size_t outer = 0, inner = 0;
    for (int i = 0; i < 4; ++i)
        (b.rest->opp(int32_t(4 * t + i)) == viscera::sim::kNone ? outer : inner) += 1;
    std::vector<uint8_t> mask(b.rest->tetCount(), 1);
    mask[t] = 0;
    b.view.setBodyCut(0, mask);
    EXPECT_EQ(body.drawnTriangleCount(), body.triangleCount() - outer);
    EXPECT_EQ(cutMesh.drawnTriangleCount(), inner);
    b.view.setBodyCut(0, std::vector<uint8_t>(b.rest->tetCount(), 0));
    EXPECT_EQ(body.drawnTriangleCount(), 0u);
    EXPECT_EQ(cutMesh.drawnTriangleCount(), 0u);
}

TEST(BodyCut, PastTheCapacityTheFirstFacesAreShownAndAllAreCounted) {
    CutBody b(2);
    std::vector<uint8_t> mask(b.rest->tetCount(), 1);
    mask[b.interiorTet()] = 0;
    b.view.setBodyCut(0, mask);
    EXPECT_EQ(b.view.exposedCutFaces(0), 4u);
    EXPECT_EQ(b.view.meshes()[b.cut].drawnTriangleCount(), 2u);
    EXPECT_THROW(b.view.addBodyCut(b.cut + 5, *b.rest), std::out_of_range);
    SceneView other;
    other.addMaterial(defaultMaterialFor("fat"));
    other.addMesh("box", viscera::sim::makeBoxSurface(viscera::sim::Vec3(0, 0, 0), viscera::sim::Vec3(1, 1, 1)), 0);
    EXPECT_THROW(other.addBodyCut(0, *b.rest), std::invalid_argument) << "not a body's boundary";
}

// From a World whose hook cuts the fat: fromWorld adds the cut mesh, updateFromWorld fills it.
TEST(BodyCut, UpdateFromWorldShowsTheFatTheHookOpened) {
    using namespace viscera::sim;
    test::Rig rig = test::makeRig();
    InteractionDesc& in = *rig.scene.interaction;
    in.tissues.push_back({"fat", 160, 0.4, Vec3(0.1, 0.3, 1.0)});
    for (InstrumentDesc& d : in.instruments)
        if (d.kind == InstrumentDesc::Kind::EnergyHook) // down through the fascia into the fat
            d.trackText = std::string(test::kHeader) + "0.00 0.008 0.015 0.0060 0 0 -1 1 1\n"
                                                       "0.50 0.032 0.015 0.0060 0 0 -1 1 1\n";
    std::unique_ptr<World> w = test::assemble(std::move(rig));
    SceneView view = SceneView::fromWorld(*w);
    size_t cutMesh = view.meshes().size();
    for (size_t i = 0; i < view.meshes().size(); ++i)
        if (view.meshes()[i].name == "fat cut surface") cutMesh = i;
    ASSERT_LT(cutMesh, view.meshes().size()) << "fromWorld adds the cut mesh of the dissected body";
    for (int f = 0; f < 30; ++f)
        w->step();
    view.updateFromWorld(*w);
    const int tets = w->interaction()->summary().fatTetsCut;
    ASSERT_GT(tets, 0) << "the hook cut fat";
    const RenderMesh& m = view.meshes()[cutMesh];
    EXPECT_GT(m.drawnTriangleCount(), 0u);
    EXPECT_TRUE(m.visible);
    // Its vertices are where the fat's nodes are now, and the heat shows along the cut.
    const auto& x = w->positions(0);
    float hot = 0;
    for (size_t v = 0; v < 3 * m.drawnTriangleCount(); ++v) {
        const Vec3& p = x[size_t(m.sourceVertex[v])];
        EXPECT_NEAR(m.positions[3 * v], p.x(), 1e-6);
        hot = std::max(hot, m.heat[v]);
    }
    EXPECT_GT(hot, 0.0f);
}
