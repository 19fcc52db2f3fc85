// What the trainee acts with, on OpenGL [issue 18 item 1]: the instrument meshes of
// render::ToolMeshes are drawn over the tissue (mono and in both eyes of side-by-side stereo),
// the jaws' opening and the energized hook change the image, a fired clip appears. Skipped, with
// the reason, where no headless context can be made.
#include "render/headless.hpp"
#include "render/tool_meshes.hpp"
#include "sim/mesh/generators.hpp"

#include <gtest/gtest.h>

using namespace viscera::render;

namespace {

constexpr int kW = 320, kH = 240;

SceneView organ() {
    SceneView view;
    const uint32_t mat = view.addMaterial(defaultMaterialFor("liver"));
    view.addMesh(
        "liver",
        viscera::sim::makeLiverSurface(viscera::sim::Vec3::Zero(), viscera::sim::Vec3(0.1, 0.07, 0.04), 0.5, 64, 32),
        mat);
    return view;
}

/// A grasper over the organ's middle, tilted, and an energy hook beside it.
ToolPoses tools(double jaw, bool hookOn, bool clip) {
    ToolPoses p;
    ToolPoses::Instrument g;
    g.name = "grasper";
    g.kind = "grasper";
    g.tip = Eigen::Vector3d(-0.015, 0.0, 0.045);
    g.direction = Eigen::Vector3d(0.5, 0.2, -0.85).normalized();
    g.jaw = jaw;
    p.instruments.push_back(g);
    ToolPoses::Instrument h;
    h.name = "hook";
    h.kind = "energy_hook";
    h.tip = Eigen::Vector3d(0.02, 0.0, 0.044);
    h.direction = Eigen::Vector3d(-0.5, -0.2, -0.85).normalized();
    h.act = hookOn;
    p.instruments.push_back(h);
    p.maxClips = 1;
    if (clip)
        p.clips.push_back({Eigen::Vector3d(0.0, -0.01, 0.043), Eigen::Vector3d(0.0, 0.01, 0.043),
                           Eigen::Vector3d(0.003, -0.01, 0.043), Eigen::Vector3d(0.003, 0.01, 0.043)});
    return p;
}

struct Rig {
    std::unique_ptr<HeadlessRenderer> r;
    RenderSettings s;
    std::string why;
    explicit Rig(const SceneView& framed, StereoMode stereo = StereoMode::Off) {
        s = defaultSettingsFor(framed, kW, kH); // framed on the tissue, as the player does
        s.post.disableAll();
        s.stereo.mode = stereo;
        if (stereo != StereoMode::Off) {
            s.stereo.eyeSeparation = 0.02f;
            s.stereo.convergenceDistance = (s.camera.target - s.camera.position).norm();
        }
        r = HeadlessRenderer::create(s, &why);
    }
    Image draw(const SceneView& v) {
        r->renderFrame(v);
        return r->readPixels(ImageStage::Final); // stereo: both eyes composed
    }
};

Image half(const Image& img, int which) {
    Image h;
    h.width = img.width / 2;
    h.height = img.height;
    for (int y = 0; y < img.height; ++y)
        h.rgba.insert(h.rgba.end(), img.pixel(which * h.width, y), img.pixel(which * h.width, y) + 4 * h.width);
    return h;
}

} // namespace

TEST(RenderGlTools, InstrumentsAreDrawnAndTheirStateShows) {
    SceneView bare = organ();
    Rig rig(bare);
    if (!rig.r) GTEST_SKIP() << "no headless OpenGL context: " << rig.why;
    const Image without = rig.draw(bare);

    SceneView view = organ();
    ToolMeshes meshes(view, tools(1.0, false, false));
    ASSERT_EQ(meshes.meshCount(), 3u); // grasper, hook, the one clip the case can fire
    const Image open = rig.draw(view);
    const size_t drawn = compareImages(without, open).differing;
    EXPECT_GT(drawn, 400u) << "the instruments cover part of the view";
    EXPECT_LT(drawn, size_t(kW * kH) / 2) << "but do not hide the tissue";

    meshes.update(view, tools(0.0, false, false)); // jaws closed
    const Image closed = rig.draw(view);
    EXPECT_GT(compareImages(open, closed).differing, 20u) << "the jaws moved";

    meshes.update(view, tools(0.0, true, false)); // hook energized: highlighted material
    const Image hot = rig.draw(view);
    EXPECT_GT(compareImages(closed, hot).differing, 20u) << "the energized hook looks different";

    meshes.update(view, tools(0.0, true, true)); // the clip fired
    const Image clipped = rig.draw(view);
    EXPECT_GT(compareImages(hot, clipped).differing, 10u) << "the fired clip appears";
    writePng(std::string(VISCERA_TEST_OUTPUT_DIR) + "/tools_mono.png", clipped); // to look at
}

TEST(RenderGlTools, StereoDrawsTheInstrumentsInBothEyes) {
    SceneView bare = organ();
    Rig rig(bare, StereoMode::SideBySide);
    if (!rig.r) GTEST_SKIP() << "no headless OpenGL context: " << rig.why;
    const Image without = rig.draw(bare);
    SceneView view = organ();
    ToolMeshes meshes(view, tools(0.5, false, true));
    const Image with = rig.draw(view);
    for (int eye = 0; eye < 2; ++eye)
        EXPECT_GT(compareImages(half(without, eye), half(with, eye)).differing, 150u) << "eye " << eye;
    // Parallax: the instruments are not at the same place in the two eyes.
    EXPECT_GT(compareImages(half(with, 0), half(with, 1)).differing, 50u);
    writePng(std::string(VISCERA_TEST_OUTPUT_DIR) + "/tools_stereo.png", with);
}

// The fat's cut surface is drawn: with the tets of a corner cut away, hiding the cut mesh changes
// the image (what shows through the opening is the cavity's faces, not the background).
TEST(RenderGlTools, TheFatsCutSurfaceIsDrawnInTheOpening) {
    using namespace viscera::sim;
    BoxSpec spec;
    spec.size = Vec3(0.04, 0.03, 0.02);
    spec.cells = {8, 6, 4};
    const std::unique_ptr<TetMesh> rest = makeBoxTetMesh(spec);
    rest->requireLevel(3);
    SceneView view;
    view.addMaterial(defaultMaterialFor("fat"));
    view.meshes().push_back(bodySurfaceMesh(*rest, "fat", 0));
    const size_t cut = view.addBodyCut(0, *rest);
    Rig r(view);
    if (!r.r) GTEST_SKIP() << "no headless OpenGL context: " << r.why;
    // Cut every tet whose centroid lies in the upper front quarter (a notch open to the camera).
    std::vector<uint8_t> mask(rest->tetCount(), 1);
    for (size_t t = 0; t < rest->tetCount(); ++t) {
        Vec3 c = Vec3::Zero();
        for (int32_t v : rest->tets()[t])
            c += rest->positions()[size_t(v)] / 4;
        if (c.z() > 0.01 && c.x() > 0.02) mask[t] = 0;
    }
    view.setBodyCut(0, mask);
    ASSERT_GT(view.exposedCutFaces(0), 0u);
    for (size_t i = 0; i < view.meshes().size(); ++i) { // the copy from the source, as updateFromWorld does
        RenderMesh& m = view.meshes()[i];
        for (size_t v = 0; v < m.vertexCount(); ++v)
            for (int a = 0; a < 3; ++a)
                m.positions[3 * v + a] = float(rest->positions()[size_t(m.sourceVertex[v])][a]);
        view.recomputeNormals(i);
    }
    const Image with = r.draw(view);
    view.meshes()[cut].visible = false;
    const Image without = r.draw(view);
    EXPECT_GT(compareImages(with, without).differing, 300u) << "the cavity's faces are drawn";
    writePng(std::string(VISCERA_TEST_OUTPUT_DIR) + "/fat_cut.png", with);
}
