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
