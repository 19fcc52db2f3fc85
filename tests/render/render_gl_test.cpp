// Headless OpenGL tests (EGL, Mesa llvmpipe): golden images of the unprocessed frame, of every
// post effect [A §6.3.3], of stereo output [B ch. 4] and of the heat tint; the exact identity of
// "all effects off" with the unprocessed image; in-place mesh updates; area-light sampling against
// the many-sample reference [A §6.3.2]. Skipped, with the reason, where no context can be created
// (render_gl_context_available fails there).
//
// Goldens: tests/render/golden/<name>.png, compared with a tolerance (RMSE ≤ 1.5, max channel
// difference ≤ 64 in 8-bit units). Regenerate with VISCERA_UPDATE_GOLDENS=1: the test then writes
// the file and fails on purpose so a regeneration is never silent.
#include "render/headless.hpp"
#include "sim/mesh/generators.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>

using namespace viscera::render;
namespace fs = std::filesystem;

namespace {

constexpr int kW = 160, kH = 120;

SceneView organView() {
    SceneView v;
    const uint32_t mat = v.addMaterial(defaultMaterialFor("liver"));
    v.addMesh(
        "liver",
        viscera::sim::makeLiverSurface(viscera::sim::Vec3::Zero(), viscera::sim::Vec3(0.1, 0.07, 0.04), 0.5, 64, 32),
        mat);
    return v;
}

RenderSettings baseSettings(const SceneView& v) {
    RenderSettings s = defaultSettingsFor(v, kW, kH);
    s.post.disableAll();
    // Effect parameters strong enough to show at 160×120.
    s.post.chromaticAberration.strength = 0.02f;
    s.post.noise.amount = 0.06f;
    s.post.sharpen.amount = 1.5f;
    s.post.depthOfField.focusDistance = (s.camera.target - s.camera.position).norm() - 0.03f;
    s.post.depthOfField.focusRange = 0.005f;
    s.post.depthOfField.blurPerMetre = 300.0f;
    s.post.radialMask.inner = 0.4f;
    s.post.radialMask.outer = 0.9f;
    return s;
}

class RenderGl : public ::testing::Test {
protected:
    void SetUp() override {
        view = organView();
        settings = baseSettings(view);
        std::string why;
        renderer = HeadlessRenderer::create(settings, &why);
        if (!renderer) GTEST_SKIP() << "no headless OpenGL context: " << why;
    }
    Image render(const RenderSettings& s, ImageStage stage = ImageStage::Final) {
        renderer->setSettings(s);
        renderer->renderFrame(view);
        return renderer->readPixels(stage);
    }
    SceneView view;
    RenderSettings settings;
    std::unique_ptr<HeadlessRenderer> renderer;
};

void expectMatchesGolden(const std::string& name, const Image& image) {
    const fs::path golden = fs::path(VISCERA_GOLDEN_DIR) / (name + ".png");
    if (std::getenv("VISCERA_UPDATE_GOLDENS")) {
        writePng(golden, image);
        ADD_FAILURE() << "regenerated golden " << golden << " (VISCERA_UPDATE_GOLDENS is set): look at it, then rerun "
                      << "without VISCERA_UPDATE_GOLDENS";
        return;
    }
    const fs::path actual = fs::path(VISCERA_TEST_OUTPUT_DIR) / (name + ".actual.png");
    if (!fs::exists(golden)) {
        writePng(actual, image);
        FAIL() << "golden " << golden << " is missing; the rendered image is " << actual
               << "; create goldens with VISCERA_UPDATE_GOLDENS=1";
    }
    const Image expected = readPng(golden);
    ASSERT_EQ(expected.width, image.width) << name;
    ASSERT_EQ(expected.height, image.height) << name;
    const ImageDifference d = compareImages(expected, image);
    if (d.rmse > 1.5 || d.maxChannel > 64) writePng(actual, image);
    EXPECT_LE(d.rmse, 1.5) << name << ": rendered image written to " << actual;
    EXPECT_LE(d.maxChannel, 64) << name << ": rendered image written to " << actual;
}

} // namespace

TEST_F(RenderGl, ContextIsOpenGl4) {
    RecordProperty("device", renderer->description());
    EXPECT_NE(renderer->description().find("OpenGL 4."), std::string::npos) << renderer->description();
}

TEST_F(RenderGl, UnprocessedGolden) {
    const Image img = render(settings);
    // The organ is lit and stands out from the dark background.
    const uint8_t* centre = img.pixel(kW / 2, kH / 2);
    const uint8_t* corner = img.pixel(1, 1);
    EXPECT_GT(int(centre[0]), int(corner[0]) + 30);
    EXPECT_GT(centre[0], centre[2]); // tissue is red
    expectMatchesGolden("unprocessed", img);
}

TEST_F(RenderGl, AllEffectsOffEqualsUnprocessedExactly) {
    RenderSettings all = settings;
    all.post.depthOfField.enabled = all.post.chromaticAberration.enabled = all.post.toneMapping.enabled = true;
    all.post.colourCurve.enabled = all.post.sharpen.enabled = all.post.noise.enabled = all.post.radialMask.enabled =
        true;
    const Image processed = render(all);
    EXPECT_GT(compareImages(processed, renderer->readPixels(ImageStage::Unprocessed)).differing, 1000u);

    const Image off = render(settings); // every effect off again
    for (const PassTiming& p : renderer->lastFrame().passes)
        EXPECT_TRUE(p.name == "gbuffer" || p.name == "lighting" || p.name == "output") << p.name;
    const ImageDifference d = compareImages(off, renderer->readPixels(ImageStage::Unprocessed));
    EXPECT_EQ(d.differing, 0u);
    EXPECT_EQ(d.maxChannel, 0);
}

struct EffectCase {
    const char* name;
    void (*enable)(PostSettings&);
};

void PrintTo(const EffectCase& c, std::ostream* os) {
    *os << c.name;
}

class RenderGlEffect : public RenderGl, public ::testing::WithParamInterface<EffectCase> {};

TEST_P(RenderGlEffect, GoldenAndVisible) {
    const Image base = render(settings);
    RenderSettings s = settings;
    GetParam().enable(s.post);
    const Image img = render(s);
    ASSERT_EQ(renderer->lastFrame().passes.size(), 4u); // gbuffer, lighting, the effect, output
    EXPECT_EQ(renderer->lastFrame().passes[2].name, GetParam().name);
    EXPECT_GT(compareImages(base, img).differing, size_t(kW * kH / 100)) << "the effect changed nothing";
    expectMatchesGolden(std::string("post_") + GetParam().name, img);
}

INSTANTIATE_TEST_SUITE_P(
    PostEffects, RenderGlEffect,
    ::testing::Values(EffectCase{"depth_of_field", [](PostSettings& p) { p.depthOfField.enabled = true; }},
                      EffectCase{"chromatic_aberration", [](PostSettings& p) { p.chromaticAberration.enabled = true; }},
                      EffectCase{"tone_mapping", [](PostSettings& p) { p.toneMapping.enabled = true; }},
                      EffectCase{"colour_curve", [](PostSettings& p) { p.colourCurve.enabled = true; }},
                      EffectCase{"sharpen", [](PostSettings& p) { p.sharpen.enabled = true; }},
                      EffectCase{"noise", [](PostSettings& p) { p.noise.enabled = true; }},
                      EffectCase{"radial_mask", [](PostSettings& p) { p.radialMask.enabled = true; }}),
    [](const ::testing::TestParamInfo<EffectCase>& info) { return std::string(info.param.name); });

TEST_F(RenderGl, StereoSideBySideGolden) {
    RenderSettings s = settings;
    s.stereo.mode = StereoMode::SideBySide;
    s.stereo.eyeSeparation = 0.02f; // exaggerated so the halves differ at this size
    s.stereo.convergenceDistance = (s.camera.target - s.camera.position).norm();
    const Image img = render(s);
    Image left, right;
    left.width = right.width = kW / 2;
    left.height = right.height = kH;
    for (int y = 0; y < kH; ++y) {
        left.rgba.insert(left.rgba.end(), img.pixel(0, y), img.pixel(0, y) + 4 * (kW / 2));
        right.rgba.insert(right.rgba.end(), img.pixel(kW / 2, y), img.pixel(kW / 2, y) + 4 * (kW / 2));
    }
    const ImageDifference d = compareImages(left, right);
    EXPECT_GT(d.differing, 50u); // parallax
    EXPECT_LT(d.rmse, 40.0);     // but the same view
    expectMatchesGolden("stereo_side_by_side", img);
}

TEST_F(RenderGl, StereoAnaglyphGolden) {
    RenderSettings s = settings;
    s.stereo.mode = StereoMode::Anaglyph;
    s.stereo.eyeSeparation = 0.02f;
    s.stereo.convergenceDistance = (s.camera.target - s.camera.position).norm();
    const Image img = render(s);
    EXPECT_EQ(renderer->lastFrame().passes.back().name, "stereo_compose");
    expectMatchesGolden("stereo_anaglyph", img);
}

TEST_F(RenderGl, HeatTintGolden) {
    const Image fresh = render(settings);
    RenderMesh& m = view.meshes()[0];
    std::vector<float> heat(m.vertexCount());
    for (size_t v = 0; v < heat.size(); ++v)
        heat[v] = std::max(0.0f, 1.0f - std::abs(m.positions[3 * v]) / 0.02f);
    view.setHeat(0, heat);
    const Image hot = render(settings);
    // Coagulated tissue (x ≈ ±0.015 m) turns pale; the charred centre line darkens. Both change the image.
    EXPECT_GT(compareImages(fresh, hot).differing, size_t(kW * kH / 50));
    expectMatchesGolden("heat_tint", hot);
}

TEST_F(RenderGl, OverlayTintsTheSurfaceByItsAlphaAndNoneLeavesItAsItWas) {
    const Image plain = render(settings);
    RenderMesh& m = view.meshes()[0];
    // left half (x < 0) fully blue, right half untouched (alpha 0)
    std::vector<float> rgba(4 * m.vertexCount(), 0.0f);
    for (size_t v = 0; v < m.vertexCount(); ++v)
        if (m.positions[3 * v] < 0) {
            rgba[4 * v + 2] = 1.0f;
            rgba[4 * v + 3] = 1.0f;
        }
    view.setOverlay(0, rgba);
    const Image tinted = render(settings);
    EXPECT_GT(compareImages(plain, tinted).differing, size_t(kW * kH / 50));
    // the painted side is bluer than it was, on average over the pixels that changed
    double blueGain = 0, redGain = 0;
    size_t changed = 0;
    for (size_t p = 0; p + 3 < plain.rgba.size(); p += 4)
        if (plain.rgba[p] != tinted.rgba[p] || plain.rgba[p + 2] != tinted.rgba[p + 2]) {
            blueGain += double(tinted.rgba[p + 2]) - plain.rgba[p + 2];
            redGain += double(tinted.rgba[p]) - plain.rgba[p];
            ++changed;
        }
    ASSERT_GT(changed, 0u);
    EXPECT_GT(blueGain / changed, 5.0);
    EXPECT_LT(redGain / changed, 0.0);
    // clearing the overlay gives the plain frame back exactly
    view.setOverlay(0, {});
    EXPECT_EQ(compareImages(plain, render(settings)).differing, 0u);
}

TEST_F(RenderGl, TranslucentMeshIsDrawnInEveryOtherPixel) {
    // the studio's paint tools draw a body translucent (a screen door) so its skeleton shows
    auto drawnPixels = [&](int parity[2]) {
        render(settings);
        const std::vector<float> d = renderer->renderer().distanceMap(Eigen::Vector3f::Zero());
        size_t n = 0;
        parity[0] = parity[1] = 0;
        for (int y = 0; y < kH; ++y)
            for (int x = 0; x < kW; ++x)
                if (d[size_t(y) * kW + x] >= 0) {
                    ++n;
                    ++parity[(x + y) & 1];
                }
        return n;
    };
    int p[2];
    const size_t opaque = drawnPixels(p);
    ASSERT_GT(opaque, size_t(kW * kH / 10));
    EXPECT_GT(std::min(p[0], p[1]), int(opaque / 3)) << "both parities drawn when opaque";
    view.meshes()[0].translucent = true;
    const size_t door = drawnPixels(p);
    EXPECT_NEAR(double(door) / opaque, 0.5, 0.02);
    EXPECT_EQ(std::min(p[0], p[1]), 0) << "every other pixel: one parity only";
    view.meshes()[0].translucent = false;
    EXPECT_EQ(drawnPixels(p), opaque);
}

TEST_F(RenderGl, DeformingMeshesUpdateInPlace) {
    const Image first = render(settings);
    const BackendStats before = renderer->renderer().backend().stats();
    for (int f = 0; f < 4; ++f) {
        for (size_t v = 0; v < view.meshes()[0].vertexCount(); ++v)
            view.meshes()[0].positions[3 * v + 2] *= 0.9f;
        view.recomputeNormals(0);
        renderer->renderFrame(view);
    }
    const BackendStats after = renderer->renderer().backend().stats();
    EXPECT_EQ(after.bufferAllocations, before.bufferAllocations);
    EXPECT_EQ(after.targetAllocations, before.targetAllocations);
    EXPECT_GE(after.bufferUpdates, before.bufferUpdates + 4 * 3);
    EXPECT_GT(compareImages(first, renderer->readPixels()).differing, 500u);
}

TEST_F(RenderGl, AdaptiveSamplingBeatsUniformNearTheLight) {
    // A large light close beside the thick end of the organ, where an area light and a point light
    // differ most [A Fig. 6.12].
    RenderSettings s = settings;
    s.width = 200;
    s.height = 150;
    s.light.followCamera = false;
    s.light.center = {0.125f, -0.02f, 0.045f};
    s.light.direction = Eigen::Vector3f(-1.0f, 0.2f, -0.6f).normalized();
    s.light.width = 0.05f;
    s.light.height = 0.03f;
    s.light.intensity = 0.015f;
    s.sampling.bands = {{0.07f, 8}, {0.1f, 4}, {INFINITY, 1}};
    s.sampling.mode = SampleMode::Reference;
    const Image reference = render(s);
    const std::vector<float> dist = renderer->renderer().distanceMap(renderer->renderer().light().center);
    std::vector<uint8_t> nearMask(dist.size());
    size_t nearPixels = 0;
    for (size_t i = 0; i < dist.size(); ++i)
        nearPixels += nearMask[i] = dist[i] >= 0 && dist[i] <= 0.07f;
    ASSERT_GT(nearPixels, 300u);
    s.sampling.mode = SampleMode::Uniform;
    s.sampling.uniformSamples = 1;
    const double uniform = compareImages(reference, render(s), nearMask).rmse;
    s.sampling.mode = SampleMode::Distance;
    const double distance = compareImages(reference, render(s), nearMask).rmse;
    RecordProperty("rmse_uniform1_near", std::to_string(uniform));
    RecordProperty("rmse_distance_near", std::to_string(distance));
    EXPECT_GT(uniform, 1.0);
    EXPECT_LT(distance, 0.5 * uniform);
    // Painted: 8× within 7 cm of the light, the rest unpainted (1×).
    view.paintSampleMap(renderer->renderer().light().center, 0.07f, 8);
    s.sampling.mode = SampleMode::Painted;
    const double painted = compareImages(reference, render(s), nearMask).rmse;
    RecordProperty("rmse_painted_near", std::to_string(painted));
    EXPECT_LT(painted, 0.5 * uniform);
}

namespace {

/// w × h, every pixel `rgba` except the bottom-left quadrant, which is `corner`.
Image quadrantImage(int w, int h, std::array<uint8_t, 4> rgba, std::array<uint8_t, 4> corner) {
    Image img;
    img.width = w;
    img.height = h;
    img.rgba.resize(size_t(w) * h * 4);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            std::copy_n((x < w / 2 && y >= h / 2 ? corner : rgba).data(), 4, &img.rgba[(size_t(y) * w + x) * 4]);
    return img;
}

/// Mean of red minus green over the pixels where `drawn` (the renderer's distance map) is >= 0.
double redOverGreen(const Image& img, const std::vector<float>& drawn, size_t* count = nullptr) {
    double sum = 0;
    size_t n = 0;
    for (size_t i = 0; i < drawn.size() && 4 * i + 3 < img.rgba.size(); ++i)
        if (drawn[i] >= 0) {
            sum += double(img.rgba[4 * i]) - img.rgba[4 * i + 1];
            ++n;
        }
    if (count) *count = n;
    return n ? sum / double(n) : 0.0;
}

} // namespace

TEST_F(RenderGl, MaterialMapsReplaceTheProceduralLayersAndUploadOnce) {
    // [A §6.2.2]: a diffuse map on the organ (triplanar on the rest position: it has no UVs)
    const Image plain = render(settings, ImageStage::Unprocessed);
    SceneView empty;
    empty.addMaterial(defaultMaterialFor("liver"));
    auto maps = std::make_shared<MaterialMaps>();
    maps->diffuse = quadrantImage(64, 64, {20, 230, 20, 255}, {20, 230, 20, 255}); // all green
    maps->tilesPerMetre = 30;
    TissueMaterial mat = view.materials()[view.meshes()[0].material];
    mat.maps = maps;
    view.meshes()[0].material = view.addMaterial(mat);
    const BackendStats before = renderer->renderer().backend().stats();
    const Image mapped = render(settings, ImageStage::Unprocessed);
    if (const char* d = std::getenv("VISCERA_GL_SHOTS")) {
        writePng(fs::path(d) / "maps_plain.png", plain);
        writePng(fs::path(d) / "maps_mapped.png", mapped);
    }
    const BackendStats after = renderer->renderer().backend().stats();
    EXPECT_EQ(after.textureUploads - before.textureUploads, 1u) << "one map, uploaded on first use";
    EXPECT_EQ(after.mappedDraws - before.mappedDraws, 1u);
    render(settings, ImageStage::Unprocessed);
    EXPECT_EQ(renderer->renderer().backend().stats().textureUploads, after.textureUploads) << "not again";
    ASSERT_GT(compareImages(plain, mapped).differing, size_t(kW * kH / 10));
    // the tissue's red turns green where the map is sampled
    const std::vector<float> drawn = renderer->renderer().distanceMap(Eigen::Vector3f::Zero());
    size_t pixels = 0;
    EXPECT_GT(redOverGreen(plain, drawn, &pixels), 10.0);
    EXPECT_GT(pixels, size_t(kW * kH / 10));
    EXPECT_LT(redOverGreen(mapped, drawn), -10.0);
    // a flat normal map (0, 0, 1) leaves the shading as it was; a tilted one changes it
    maps->normal = quadrantImage(64, 64, {128, 128, 255, 255}, {128, 128, 255, 255});
    mat.maps = std::make_shared<MaterialMaps>(*maps);
    view.materials()[view.meshes()[0].material] = mat;
    const ImageDifference flat = compareImages(mapped, render(settings, ImageStage::Unprocessed));
    EXPECT_LE(flat.rmse, 1.0) << "flat normal map";
    auto tilted = std::make_shared<MaterialMaps>(*maps);
    tilted->normal = quadrantImage(64, 64, {230, 128, 180, 255}, {40, 200, 180, 255});
    mat.maps = tilted;
    view.materials()[view.meshes()[0].material] = mat;
    const ImageDifference bumped = compareImages(mapped, render(settings, ImageStage::Unprocessed));
    EXPECT_GT(bumped.rmse, 2.0) << "tilted normals change the lighting";
    std::printf("material maps: flat normal map RMSE %.3f, tilted %.3f (8-bit) against the diffuse-only frame\n",
                flat.rmse, bumped.rmse);
    // no maps: the procedural frame exactly
    view.meshes()[0].material = 0;
    EXPECT_EQ(compareImages(plain, render(settings, ImageStage::Unprocessed)).differing, 0u);
}

TEST_F(RenderGl, MeshUvsSelectTheTexelsWithVZeroAtTheImageBottom) {
    // every vertex at one UV: the whole organ shows that texel's colour
    auto maps = std::make_shared<MaterialMaps>();
    maps->diffuse = quadrantImage(64, 64, {230, 20, 20, 255}, {20, 230, 20, 255}); // green bottom-left
    TissueMaterial mat = view.materials()[view.meshes()[0].material];
    mat.maps = maps;
    view.meshes()[0].material = view.addMaterial(mat);
    RenderMesh& m = view.meshes()[0];
    auto at = [&](float u, float v) {
        m.uv.assign(2 * m.vertexCount(), 0.0f);
        for (size_t i = 0; i < m.vertexCount(); ++i) {
            m.uv[2 * i] = u;
            m.uv[2 * i + 1] = v;
        }
        ++m.staticRevision;
        const Image img = render(settings, ImageStage::Unprocessed);
        return redOverGreen(img, renderer->renderer().distanceMap(Eigen::Vector3f::Zero()));
    };
    EXPECT_LT(at(0.25f, 0.25f), -10.0) << "v = 0.25: the bottom half of the image, left: green";
    EXPECT_GT(at(0.25f, 0.75f), 10.0) << "v = 0.75: the top half: red";
    EXPECT_GT(at(0.75f, 0.25f), 10.0) << "u = 0.75: the right half: red";
}

TEST_F(RenderGl, BakedThicknessMapShadesLikeThePerVertexThicknessAndDrivesTheScattering) {
    // [A §6.3.1] the thickness per texel, sampled through the mesh's UVs, in place of the
    // per-vertex bake: the same thickness gives nearly the same frame; a thin map, a redder one
    RenderMesh& m = view.meshes()[0];
    m.uv.resize(2 * m.vertexCount());
    for (size_t v = 0; v < m.vertexCount(); ++v) { // a projection from above: no seam on the organ
        m.uv[2 * v] = 0.5f + m.rest[3 * v] / 0.25f;
        m.uv[2 * v + 1] = 0.5f + m.rest[3 * v + 1] / 0.25f;
    }
    ++m.staticRevision;
    const Image perVertex = render(settings, ImageStage::Unprocessed);
    view.bakeThicknessMap(0, 256);
    const Image mapped = render(settings, ImageStage::Unprocessed);
    const ImageDifference same = compareImages(perVertex, mapped);
    Image thin = m.thicknessMap;
    for (size_t i = 0; i < thin.rgba.size(); i += 4)
        thin.rgba[i] = thin.rgba[i + 1] = thin.rgba[i + 2] = 0;
    m.thicknessMap = thin;
    ++m.staticRevision;
    const ImageDifference thinner = compareImages(mapped, render(settings, ImageStage::Unprocessed));
    std::printf("thickness map vs per-vertex thickness: RMSE %.3f; an all-thin map: RMSE %.3f (8-bit)\n", same.rmse,
                thinner.rmse);
    EXPECT_LT(same.rmse, 1.5) << "the same thickness, per texel";
    EXPECT_GT(thinner.rmse, 3.0 * std::max(same.rmse, 0.5)) << "the map drives the scattering";
}

// A light exactly at the eye (the scope's light on its lens axis): the specular Fresnel term took
// pow() of 1 − dot(H, V) with H = V, which rounds below zero, and the highlight became NaN specks
// (black pixels) in the lit organ. Every pixel the organ covers is lit, with the light on the axis
// and beside it; the two images differ only near the highlight.
TEST_F(RenderGl, ALightAtTheEyeLeavesNoUnlitSpecksInTheHighlight) {
    RenderSettings s = settings;
    s.light.followCamera = true;
    s.sampling.mode = SampleMode::Uniform;
    s.sampling.uniformSamples = 1; // one sample at the light's centre: exactly the eye
    auto blackInside = [&](const Image& img) {
        // Pixels of the organ: where the same frame with the light beside the eye is lit.
        int black = 0;
        for (int y = kH / 4; y < 3 * kH / 4; ++y)
            for (int x = kW / 4; x < 3 * kW / 4; ++x) {
                const uint8_t* p = img.pixel(x, y);
                if (p[0] == 0 && p[1] == 0 && p[2] == 0) ++black;
            }
        return black;
    };
    s.light.cameraOffset = Eigen::Vector3f::Zero();
    const Image onAxis = render(s);
    s.light.cameraOffset = Eigen::Vector3f(0.004f, 0.0f, 0.0f);
    const Image beside = render(s);
    const uint8_t* centre = onAxis.pixel(kW / 2, kH / 2);
    EXPECT_GT(int(centre[0]), 20) << "the organ's centre is lit by a light on the axis";
    EXPECT_EQ(blackInside(onAxis), 0) << "no NaN (black) pixel in the organ with the light at the eye";
    EXPECT_EQ(blackInside(beside), 0);
}
