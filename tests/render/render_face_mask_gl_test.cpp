// Face mask on OpenGL [A §5.3.1]: masked (cut) faces disappear from the image while the index
// buffer is rewritten in place (no buffer allocation); all faces masked gives the empty image.
// Skipped, with the reason, where no headless context can be made.
#include "render/headless.hpp"
#include "sim/mesh/generators.hpp"

#include <gtest/gtest.h>

using namespace viscera::render;

TEST(RenderGlFaceMask, MaskedFacesVanishWithoutReallocation) {
    SceneView view;
    const uint32_t mat = view.addMaterial(defaultMaterialFor("liver"));
    view.addMesh(
        "liver",
        viscera::sim::makeLiverSurface(viscera::sim::Vec3::Zero(), viscera::sim::Vec3(0.1, 0.07, 0.04), 0.5, 64, 32),
        mat);
    RenderSettings s = defaultSettingsFor(view, 160, 120);
    s.post.disableAll();
    std::string why;
    auto r = HeadlessRenderer::create(s, &why);
    if (!r) GTEST_SKIP() << "no headless OpenGL context: " << why;

    r->renderFrame(view);
    const Image full = r->readPixels(ImageStage::Unprocessed);
    const BackendStats before = r->renderer().backend().stats();

    // Every face masked: the image equals the one of the hidden mesh.
    view.setFaceMask(0, std::vector<uint8_t>(view.meshes()[0].triangleCount(), 0));
    r->renderFrame(view);
    const Image none = r->readPixels(ImageStage::Unprocessed);
    view.setFaceMask(0, {});
    view.meshes()[0].visible = false;
    r->renderFrame(view);
    const Image hidden = r->readPixels(ImageStage::Unprocessed);
    view.meshes()[0].visible = true;
    EXPECT_EQ(compareImages(none, hidden).differing, 0u);
    const size_t all = compareImages(full, hidden).differing;
    EXPECT_GT(all, 1000u);

    // Half the faces (centroid x > 0) masked: part of the organ vanishes, the rest stays.
    const RenderMesh& m = view.meshes()[0];
    std::vector<uint8_t> mask(m.triangleCount(), 1);
    for (size_t f = 0; f < m.triangleCount(); ++f) {
        float cx = 0;
        for (int c = 0; c < 3; ++c)
            cx += m.positions[3 * m.indices[3 * f + c]];
        mask[f] = cx > 0 ? 0 : 1;
    }
    view.setFaceMask(0, mask);
    r->renderFrame(view);
    const Image half = r->readPixels(ImageStage::Unprocessed);
    const size_t changed = compareImages(full, half).differing;
    EXPECT_GT(changed, all / 5);
    EXPECT_LT(compareImages(half, hidden).differing, all);
    EXPECT_GT(compareImages(half, hidden).differing, all / 5);
    const BackendStats after = r->renderer().backend().stats();
    EXPECT_EQ(after.bufferAllocations, before.bufferAllocations);
}
