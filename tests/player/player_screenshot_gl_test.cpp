// End-to-end on the headless GL path: `viscera-player run <case> --headless --screenshot out.png`
// renders the last frame through EGL (Mesa llvmpipe without a GPU) and the session report gives
// the frame time per pass. Skipped with the reason when no context can be created; the dedicated
// test `render_gl_context_available` fails in that case, so a skip here cannot hide a broken
// machine.
#include "render/headless.hpp"
#include "render/image.hpp"
#include "support/case_signing.hpp"
#include "support/run_process.hpp"
#include "support/scratch_dir.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>

using namespace viscera;
using ::testing::HasSubstr;

namespace {

using test::Scratch;

/// Exports the tissue-slab sample project into the scratch folder; returns the case path.
std::string exportTissueSlab(const Scratch& s) {
    const std::string vcase = s / "tissue-slab.vcase";
    auto e = test::runProcess(
        VISCERA_STUDIO_EXE,
        test::signingWithSampleKey({"export", std::string(VISCERA_SOURCE_DIR) + "/projects/tissue-slab", "-o", vcase}));
    EXPECT_EQ(e.exitCode, 0) << e.err;
    return vcase;
}

} // namespace

TEST(PlayerScreenshot, HeadlessRunWritesARenderedFrameAndPassTimes) {
    ::setenv("LIBGL_ALWAYS_SOFTWARE", "1", 0); // llvmpipe, as the other GL tests (the child inherits it)
    std::string why;
    if (!render::headlessContextAvailable(&why)) GTEST_SKIP() << "no headless GL context: " << why;
    Scratch s("viscera-shot");
    const std::string vcase = exportTissueSlab(s);
    ASSERT_FALSE(::testing::Test::HasFailure());
    const auto png = s.dir / "frame.png", report = s.dir / "report.json";
    auto r = test::runProcess(VISCERA_PLAYER_EXE,
                              test::trustingSampleKey({"run", vcase, "--headless", "--frames", "20", "--screenshot",
                                                       png.string(), "--report", report.string()}));
    ASSERT_EQ(r.exitCode, 0) << r.err << r.out;
    EXPECT_THAT(r.out, HasSubstr("render        640x480 frame"));

    const render::Image img = render::readPng(png);
    ASSERT_EQ(img.width, 640);
    ASSERT_EQ(img.height, 480);
    // Not a blank frame: the tissue covers a good part of the image with many distinct colours.
    std::set<uint32_t> colours;
    for (size_t i = 0; i + 3 < img.rgba.size(); i += 4)
        colours.insert(uint32_t(img.rgba[i]) << 16 | uint32_t(img.rgba[i + 1]) << 8 | img.rgba[i + 2]);
    EXPECT_GT(colours.size(), 500u);

    std::ifstream in(report);
    const nlohmann::json j = nlohmann::json::parse(in);
    ASSERT_TRUE(j.contains("render"));
    const auto& rj = j["render"];
    EXPECT_GT(rj["frame_ms"].get<double>(), 0.0);
    std::set<std::string> names;
    double sum = 0;
    for (const auto& p : rj["passes"]) {
        names.insert(p["name"].get<std::string>());
        EXPECT_GE(p["ms"].get<double>(), 0.0);
        sum += p["ms"].get<double>();
    }
    EXPECT_TRUE(names.count("gbuffer")) << rj.dump();
    EXPECT_TRUE(names.count("lighting")) << rj.dump();
    EXPECT_LE(sum, rj["frame_ms"].get<double>() * (1 + 1e-9));
    EXPECT_FALSE(rj["device"].get<std::string>().empty());
}

TEST(PlayerScreenshot, TraineeWindowShowsTheRenderedView) {
    ::setenv("LIBGL_ALWAYS_SOFTWARE", "1", 0);
    std::string why;
    if (!render::headlessContextAvailable(&why)) GTEST_SKIP() << "no headless GL context: " << why;
    Scratch s("viscera-shot");
    const std::string vcase = exportTissueSlab(s);
    ASSERT_FALSE(::testing::Test::HasFailure());
    const auto png = s.dir / "window.png";
    ::setenv("QT_QPA_PLATFORM", "offscreen", 1);
    auto r = test::runProcess(VISCERA_PLAYER_EXE,
                              test::trustingSampleKey({"run", vcase, "--frames", "20", "--screenshot", png.string()}));
    ::unsetenv("QT_QPA_PLATFORM");
    if (r.exitCode == 2 && r.err.find("Qt6 Gui") != std::string::npos) GTEST_SKIP() << "player built without Qt6 Gui";
    ASSERT_EQ(r.exitCode, 0) << r.err << r.out;
    EXPECT_THAT(r.err, ::testing::Not(HasSubstr("3D view off")));
    const render::Image img = render::readPng(png);
    ASSERT_GT(img.width, 400);
    // The view pane (left of the HUD panel, below the header) holds the rendered tissue: many
    // distinct shades, where the fallback side view has a handful of flat dot colours.
    std::set<uint32_t> colours;
    for (int y = 100; y < img.height - 20; ++y)
        for (int x = 20; x < img.width - 290; ++x) {
            const uint8_t* px = img.pixel(x, y);
            colours.insert(uint32_t(px[0]) << 16 | uint32_t(px[1]) << 8 | px[2]);
        }
    EXPECT_GT(colours.size(), 1000u);
}

TEST(PlayerScreenshot, TheKidneyMadeFromRenderAnatomyShowsItsTexture) {
    ::setenv("LIBGL_ALWAYS_SOFTWARE", "1", 0);
    std::string why;
    if (!render::headlessContextAvailable(&why)) GTEST_SKIP() << "no headless GL context: " << why;
    Scratch s("viscera-kidney-shot");
    auto k = test::runProcess(VISCERA_STUDIO_EXE, {"sample", "kidney", "-o", s / "kidney"});
    ASSERT_EQ(k.exitCode, 0) << k.err;
    const std::string vcase = s / "kidney.vcase";
    auto e = test::runProcess(VISCERA_STUDIO_EXE, test::signingWithSampleKey({"export", s / "kidney", "-o", vcase}));
    ASSERT_EQ(e.exitCode, 0) << e.err;
    const auto png = s.dir / "kidney.png";
    auto r = test::runProcess(VISCERA_PLAYER_EXE, test::trustingSampleKey({"run", vcase, "--headless", "--frames", "30",
                                                                           "--screenshot", png.string()}));
    ASSERT_EQ(r.exitCode, 0) << r.err << r.out;
    EXPECT_THAT(r.out, HasSubstr("all finite: yes"));
    // The atlas's colours on the body: the cortex's dark red and the pelvis's and ureter's pale
    // yellow, each over a good part of the frame (a body drawn without its UVs is one tissue colour).
    const render::Image img = render::readPng(png);
    size_t red = 0, pale = 0;
    for (size_t i = 0; i + 3 < img.rgba.size(); i += 4) {
        const int R = img.rgba[i], G = img.rgba[i + 1], B = img.rgba[i + 2];
        red += R > 45 && R > 2 * G && R > 2 * B ? 1 : 0;
        pale += R > 110 && G > 85 && B > 55 && G > R / 2 && std::abs(R - G) < 70 ? 1 : 0;
    }
    const size_t pixels = size_t(img.width) * size_t(img.height);
    EXPECT_GT(red, pixels / 100) << "cortex";
    EXPECT_GT(pale, pixels / 100) << "pelvis and ureter";
}
