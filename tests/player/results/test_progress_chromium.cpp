// The progress page in a real browser (headless Chromium, label chromium): the page loads with
// every curve decoded (the page's own script counts them into data-curves-loaded) and the
// screenshot shows the expert band. Fails, never skips, where Chromium is missing.
#include "player/results/band_pixels.hpp"
#include "player/results/report_generator.hpp"
#include "support/run_process.hpp"
#include "support/scratch_dir.hpp"

#include <gtest/gtest.h>

#include <filesystem>

namespace {

namespace fs = std::filesystem;

TEST(ResultsChromium, ProgressPageLoadsEveryCurve) {
    const std::string chromium = VISCERA_CHROMIUM_EXE;
    ASSERT_FALSE(chromium.empty() || chromium.find("NOTFOUND") != std::string::npos)
        << "chromium not found (install it: scripts/install-deps.sh)";
    viscera::test::Scratch scratch("viscera-results-chromium");
    const std::string db = scratch / "results.sqlite";
    std::vector<std::string> add{"add"};
    for (const auto& p : viscera::test::writeReports(scratch.dir, "t01", 10, true))
        add.push_back(p.string());
    add.insert(add.end(), {"--db", db});
    ASSERT_EQ(viscera::test::runProcess(VISCERA_RESULTS_EXE, add).exitCode, 0);
    const fs::path dir = scratch.dir / "progress";
    const auto made = viscera::test::runProcess(VISCERA_RESULTS_EXE,
                                                {"progress", "--trainee", "t01", "-o", dir.string(), "--db", db});
    ASSERT_EQ(made.exitCode, 0) << made.err;

    const std::string url = "file://" + (dir / "progress.html").string();
    const std::vector<std::string> common{"--headless",
                                          "--no-sandbox",
                                          "--disable-gpu",
                                          "--no-first-run",
                                          "--user-data-dir=" + scratch / "profile",
                                          "--virtual-time-budget=5000"};
    auto dumpArgs = common;
    dumpArgs.insert(dumpArgs.end(), {"--dump-dom", url});
    const auto dom = viscera::test::runProcess(chromium, dumpArgs);
    ASSERT_EQ(dom.exitCode, 0) << dom.err;
    EXPECT_NE(dom.out.find("data-curves-loaded=\"3/3\""), std::string::npos)
        << "not every curve decoded in the browser:\n"
        << dom.out.substr(0, 600);

    const std::string shot = scratch / "progress-screenshot.png";
    auto shotArgs = common;
    shotArgs.insert(shotArgs.end(), {"--screenshot=" + shot, "--window-size=1200,1600", "--hide-scrollbars", url});
    const auto r = viscera::test::runProcess(chromium, shotArgs);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    ASSERT_TRUE(fs::exists(shot)) << r.err;
    EXPECT_GT(viscera::test::bandPixels(shot, 6), 2000) << "the screenshot does not show the expert band";
    if (const char* keep = std::getenv("VISCERA_KEEP_SCREENSHOT"))
        fs::copy_file(shot, keep, fs::copy_options::overwrite_existing);
}

} // namespace
