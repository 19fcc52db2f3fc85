// The trainee window under Xvfb, driven by synthetic X input (xdotool, XTEST): a click gives the
// window the focus and the S key switches its view to side-by-side stereo. Checked on the window's
// own screenshot: in side by side the view's two halves are nearly the same picture (two eyes 5 mm
// apart), where in mono they are two different parts of one. Label gui: its step of the test
// command runs under xvfb-run and fails when no display can be opened.
#include "render/image.hpp"
#include "support/case_signing.hpp"
#include "support/run_process.hpp"
#include "support/scratch_dir.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>

using namespace viscera;

namespace {

constexpr const char* kXdotool = "/usr/bin/xdotool";

/// Mean absolute difference (0–255) between the left and right halves of the view pane
/// (the window's left part below the header: x in [24, 686), y in [96, 576)).
double halvesDifference(const render::Image& img) {
    const int x0 = 24, x1 = 686, y0 = 96, y1 = 576, half = (x1 - x0) / 2;
    double sum = 0;
    long n = 0;
    for (int y = y0; y < y1 && y < img.height; y += 2)
        for (int x = x0; x < x0 + half && x + half < img.width; x += 2) {
            const uint8_t *a = img.pixel(x, y), *b = img.pixel(x + half, y);
            for (int c = 0; c < 3; ++c)
                sum += std::abs(int(a[c]) - int(b[c]));
            n += 3;
        }
    return n > 0 ? sum / double(n) : 0.0;
}

/// Runs the window for `frames` frames; with `pressS`, clicks into it and presses S once it is up.
render::Image runWindow(const test::Scratch& s, const std::string& vcase, const std::string& name, bool pressS) {
    const std::string png = s / (name + ".png");
    test::Background player(
        VISCERA_PLAYER_EXE,
        test::trustingSampleKey({"run", vcase, "--frames", "360", "--device", "scripted:idle", "--screenshot", png}),
        s / name);
    if (pressS) {
        // At most 60 s for the window to appear (a player that died would leave --sync waiting).
        const test::ProcessResult found =
            test::runProcess("/usr/bin/timeout", {"60", kXdotool, "search", "--sync", "--name", "Viscera"});
        EXPECT_EQ(found.exitCode, 0) << found.err;
        const std::string id = found.out.substr(0, found.out.find('\n'));
        EXPECT_FALSE(id.empty()) << "the trainee window never appeared";
        std::this_thread::sleep_for(std::chrono::milliseconds(500)); // the first frame is drawn
        EXPECT_EQ(test::runProcess(kXdotool, {"mousemove", "--window", id, "300", "300", "click", "1"}).exitCode, 0);
        std::this_thread::sleep_for(std::chrono::milliseconds(300));
        EXPECT_EQ(test::runProcess(kXdotool, {"key", "s"}).exitCode, 0);
    }
    EXPECT_EQ(player.waitFor(), 0) << name;
    return render::readPng(png);
}

} // namespace

TEST(TraineeWindowGui, TheSKeySwitchesTheViewToSideBySideStereo) {
    ASSERT_NE(std::getenv("DISPLAY"), nullptr) << "no X display (run under xvfb-run)";
    ASSERT_TRUE(std::filesystem::exists(kXdotool)) << kXdotool << " is missing (scripts/install-deps.sh)";
    ::setenv("LIBGL_ALWAYS_SOFTWARE", "1", 0);
    ::unsetenv("QT_QPA_PLATFORM"); // the xcb window on the Xvfb display, not offscreen
    test::Scratch s("viscera-window");
    const std::string vcase = s / "tissue-slab.vcase";
    auto e = test::runProcess(
        VISCERA_STUDIO_EXE,
        test::signingWithSampleKey({"export", std::string(VISCERA_SOURCE_DIR) + "/projects/tissue-slab", "-o", vcase}));
    ASSERT_EQ(e.exitCode, 0) << e.err;
    const render::Image mono = runWindow(s, vcase, "mono", false);
    const render::Image stereo = runWindow(s, vcase, "stereo", true);
    ASSERT_GT(mono.width, 700);
    ASSERT_GT(stereo.width, 700);
    const double dm = halvesDifference(mono), ds = halvesDifference(stereo);
    std::printf("view halves differ by %.2f (mono) and %.2f (after S: side by side)\n", dm, ds);
    EXPECT_LT(ds, 0.5 * dm) << "after S the view shows the two eyes side by side";
}
