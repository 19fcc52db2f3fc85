// End-to-end suturing [B ch. 4]: viscera-studio exports projects/anastomosis (two hollow tubes, a
// recorded needle trajectory with 52 punctures and the thread pull), viscera-player runs it headless
// and reports per-frame step time, active constraint rows, thread tension, and the closure.
#include "case/zip_craft.hpp"
#include "support/case_signing.hpp"
#include "support/run_process.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>

using namespace viscera;
using ::testing::HasSubstr;
using vcase::test::ScratchDir;

namespace {

test::ProcessResult player(const std::vector<std::string>& args) {
    return test::runProcess(VISCERA_PLAYER_EXE, test::trustingSampleKey(args));
}
test::ProcessResult studio(const std::vector<std::string>& args) {
    return test::runProcess(VISCERA_STUDIO_EXE, test::signingWithSampleKey(args));
}

nlohmann::json readJson(const std::filesystem::path& p) {
    std::ifstream in(p);
    return nlohmann::json::parse(in);
}

bool has(const nlohmann::json& list, const std::string& s) {
    return std::find(list.begin(), list.end(), s) != list.end();
}

} // namespace

TEST(SutureCase, AnastomosisExportsRunsAndClosesTheGap) {
    ScratchDir dir;
    const auto out = dir.path() / "anastomosis.vcase";
    auto e = studio({"export", std::string(VISCERA_SOURCE_DIR) + "/projects/anastomosis", "-o", out.string()});
    ASSERT_EQ(e.exitCode, 0) << e.err;
    EXPECT_THAT(e.out, HasSubstr("features: contact fem needle thread"));
    auto v = player({"verify", out.string()});
    ASSERT_EQ(v.exitCode, 0) << v.err;
    const auto report = dir.path() / "r.json";
    // 2130 frames: 13 stitches (52 punctures), the needle parked, then the pull.
    auto r = player({"run", out.string(), "--headless", "--frames", "2130", "--report", report.string()});
    ASSERT_EQ(r.exitCode, 0) << r.err << r.out;
    EXPECT_THAT(r.out, HasSubstr("closure"));
    const nlohmann::json doc = readJson(report);
    const auto& active = doc["active_subsystems"];
    for (const char* s : {"fem", "needle", "thread", "contact"})
        EXPECT_TRUE(has(active, s)) << s;
    EXPECT_FALSE(has(active, "xpbd"));
    EXPECT_TRUE(doc["invariants"]["all_finite"].get<bool>());
    ASSERT_EQ(doc["frames"].size(), 2130u);
    for (const auto& f : doc["frames"])
        ASSERT_TRUE(std::isfinite(f["step_ms"].get<double>()));
    const nlohmann::json& s = doc["suture"];
    EXPECT_GE(s["punctures"].get<int>(), 50);
    EXPECT_EQ(doc["metrics"]["punctures"].get<int>(), s["punctures"].get<int>());
    EXPECT_NEAR(s["initial_gap_m"].get<double>(), 0.002, 1e-6);
    EXPECT_LT(s["max_gap_m"].get<double>(), 0.0002);       // 2 mm → closed (0.09 mm measured)
    EXPECT_LE(s["max_penetration_m"].get<double>(), 1e-4); // no interpenetration beyond 0.1 mm
    EXPECT_GT(s["max_thread_tension_n"].get<double>(), 0.0);
    ASSERT_EQ(s["frames"].size(), 2130u);
    int withRows = 0;
    for (const auto& f : s["frames"]) {
        ASSERT_TRUE(std::isfinite(f["thread_tension_n"].get<double>()));
        withRows += f["active_rows"].get<int>() > 0;
    }
    EXPECT_GT(withRows, 100);
    EXPECT_TRUE(s["frames"][0].contains("max_gap_m")); // sampled every 10th frame
}

TEST(SutureCase, BrokenSutureSectionsAreRejectedAtExport) {
    ScratchDir dir;
    std::ifstream in(std::string(VISCERA_SOURCE_DIR) + "/projects/anastomosis/project.json");
    nlohmann::json project = nlohmann::json::parse(in);
    auto exportWith = [&](const nlohmann::json& p) {
        const auto pdir = dir.path() / "p";
        std::filesystem::create_directories(pdir);
        std::ofstream(pdir / "project.json") << p.dump();
        return studio({"export", pdir.string(), "-o", (dir.path() / "x.vcase").string()});
    };
    nlohmann::json p = project;
    p["suture"]["needle"]["shape"] = "hook";
    auto a = exportWith(p);
    EXPECT_EQ(a.exitCode, 1);
    EXPECT_THAT(a.err, HasSubstr("suture.needle.shape"));
    p = project;
    p["suture"]["trajectory"] = {{"file", "missing.traj"}};
    auto b = exportWith(p);
    EXPECT_EQ(b.exitCode, 1);
    EXPECT_THAT(b.err, HasSubstr("missing.traj"));
    p = project;
    p["suture"]["gauge"] = {"wide", "nothere"};
    auto c = exportWith(p);
    EXPECT_EQ(c.exitCode, 1);
    EXPECT_THAT(c.err, HasSubstr("suture.gauge"));
    p = project;
    p.erase("suture");
    auto d = exportWith(p);
    EXPECT_EQ(d.exitCode, 1);
    EXPECT_THAT(d.err, HasSubstr("solver 'fem' needs a 'suture' section"));
}

// A device drives the needle (suture "device"): the replay made by `viscera-studio replay` from
// the recorded trajectory punctures as the trajectory does; a scripted wrist roll drives the
// needle along its curve into the wall; the tissue's force reaches the device.
TEST(SutureCase, ADeviceDrivesTheNeedle) {
    ScratchDir dir;
    const std::string project = std::string(VISCERA_SOURCE_DIR) + "/projects/anastomosis";
    const auto out = dir.path() / "anastomosis.vcase";
    ASSERT_EQ(studio({"export", project, "-o", out.string()}).exitCode, 0);
    const auto made = dir.path() / "made.csv";
    // The committed replay: the whole running suture (13 stitches and the pull, 2130 frames).
    auto m = studio({"replay", project, "-o", made.string(), "--frames", "2130"});
    ASSERT_EQ(m.exitCode, 0) << m.err;
    EXPECT_THAT(m.out, HasSubstr("2130 frames"));
    std::ifstream a(made), b(project + "/replays/running-suture.csv");
    const std::string madeText((std::istreambuf_iterator<char>(a)), {}), kept((std::istreambuf_iterator<char>(b)), {});
    EXPECT_EQ(madeText, kept) << "the committed replay is what `viscera-studio replay` makes";

    const auto scripted = dir.path() / "s.json";
    ASSERT_EQ(player({"run", out.string(), "--headless", "--frames", "160", "--report", scripted.string()}).exitCode,
              0);
    const int trackPunctures = readJson(scripted)["suture"]["punctures"].get<int>();
    const auto replayed = dir.path() / "r.json";
    auto r = player({"run", out.string(), "--headless", "--frames", "160", "--device", "replay:" + made.string(),
                     "--report", replayed.string()});
    ASSERT_EQ(r.exitCode, 0) << r.err << r.out;
    const nlohmann::json rd = readJson(replayed);
    EXPECT_EQ(rd["suture"]["punctures"].get<int>(), trackPunctures);
    EXPECT_GT(trackPunctures, 0);
    EXPECT_GT(rd["metrics"]["device_max_force_n"].get<double>(), 0.0);
    EXPECT_EQ(rd["haptics"]["tools"][0]["name"], "needle");
    EXPECT_EQ(rd["haptics"]["tools"][1]["name"], "thread");
    int timelinePunctures = 0; // the report's timeline has each puncture, by the needle
    for (const auto& e : rd["timeline"]["events"])
        if (e["kind"] == "puncture") {
            EXPECT_EQ(e["tool"], "needle");
            timelinePunctures += e["count"].get<int>();
        }
    EXPECT_EQ(timelinePunctures, trackPunctures);
    EXPECT_EQ(rd["timeline"]["tools"].back()["kind"], "needle");

    const auto rolled = dir.path() / "roll.json";
    auto rl = player({"run", out.string(), "--headless", "--frames", "120", "--device", "scripted:roll", "--report",
                      rolled.string()});
    ASSERT_EQ(rl.exitCode, 0) << rl.err << rl.out;
    EXPECT_THAT(rl.err, HasSubstr("tool 'thread' has no arm of this device")) << "one-arm script: warned";
    const nlohmann::json ro = readJson(rolled);
    EXPECT_GT(ro["suture"]["punctures"].get<int>(), 0) << "the roll drove the needle into the wall";
    EXPECT_GT(ro["metrics"]["device_max_force_n"].get<double>(), 0.0);
    EXPECT_TRUE(ro["invariants"]["all_finite"].get<bool>());
    EXPECT_EQ(ro["warnings"].size(), 1u);

    auto bad = studio(
        {"replay", std::string(VISCERA_SOURCE_DIR) + "/projects/tissue-slab", "-o", (dir.path() / "x.csv").string()});
    EXPECT_EQ(bad.exitCode, 1);
    EXPECT_THAT(bad.err, HasSubstr("suture: the project has no suture section"));
}
