// Assessment end to end [issue 41]: the samples exported by viscera-studio, run by
// viscera-player on their committed replays and on replays changed to miss a target. The rectum's
// dissection passes; cutting beside the marked line or clipping once fails on that metric, with
// the figure and the limit printed. The anastomosis's running suture passes; a stitch that
// misses the walls fails on its bites and their spacing. And every sample's figures agree across the summary, the
// report, the plots' reader and the HTML page.
#include "case/zip_craft.hpp"
#include "support/sample_cli.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <functional>
#include <map>
#include <regex>
#include <sstream>

using namespace viscera;
using ::testing::HasSubstr;
using vcase::test::ScratchDir;

namespace {

test::ProcessResult player(const std::vector<std::string>& args) {
    return test::samplePlayer(args);
}
test::ProcessResult studio(const std::vector<std::string>& args) {
    return test::sampleStudio(args);
}
using test::readJsonFile;
using test::readTextFile;

std::string project(const std::string& name) {
    return std::string(VISCERA_SOURCE_DIR) + "/projects/" + name;
}

/// A replay with the rows of `arm` changed by `edit` (t, fields; false drops the row).
std::filesystem::path editedReplay(const std::string& from, const std::filesystem::path& to, int arm,
                                   const std::function<bool(double, std::vector<std::string>&)>& edit) {
    std::istringstream in(readTextFile(from));
    std::ofstream out(to);
    for (std::string line; std::getline(in, line);) {
        if (line.empty() || line[0] == '#' || line[0] == 't') {
            out << line << "\n";
            continue;
        }
        std::vector<std::string> f;
        std::stringstream ss(line);
        for (std::string cell; std::getline(ss, cell, ',');)
            f.push_back(cell);
        if (std::stoi(f[1]) == arm && !edit(std::stod(f[0]), f)) continue;
        for (size_t i = 0; i < f.size(); ++i)
            out << (i ? "," : "") << f[i];
        out << "\n";
    }
    return to;
}

std::string add(const std::string& v, double d) {
    std::ostringstream s;
    s.precision(17);
    s << std::stod(v) + d;
    return s.str();
}

/// The summary's line for one metric ("metric        <name> ...").
std::string metricLine(const std::string& summary, const std::string& name) {
    std::istringstream in(summary);
    for (std::string line; std::getline(in, line);)
        if (line.rfind("metric        " + name + " ", 0) == 0) return line.substr(14);
    return "(no line for " + name + ")";
}

struct SessionRun {
    test::ProcessResult process;
    nlohmann::json report;
};

SessionRun run(const std::filesystem::path& vcase, const std::string& replay, int frames,
               const std::filesystem::path& dir, const std::string& tag) {
    const auto report = dir / (tag + ".json");
    std::vector<std::string> args = {"run",      vcase.string(),  "--headless", "--frames", std::to_string(frames),
                                     "--report", report.string(), "--trainee",  "t-01"};
    if (!replay.empty()) args.insert(args.end(), {"--device", "replay:" + replay, "--plots", (dir / tag).string()});
    SessionRun r{player(args), {}};
    EXPECT_EQ(r.process.exitCode, 0) << tag << ": " << r.process.err << r.process.out;
    if (r.process.exitCode == 0) r.report = readJsonFile(report);
    return r;
}

} // namespace

TEST(AssessmentCase, TheRectumsDissectionPassesAndCuttingAsideOrClippingOnceFails) {
    ScratchDir dir;
    const auto vcase = dir.path() / "rectum.vcase";
    ASSERT_EQ(studio({"export", project("rectum"), "-o", vcase.string()}).exitCode, 0);
    const std::string replay = project("rectum") + "/replays/dissection.csv";
    const SessionRun good = run(vcase, replay, 440, dir.path(), "good");
    EXPECT_THAT(good.process.out, HasSubstr("verdict       PASS; completion 5.88 s; within the expert level"));
    const nlohmann::json& a = good.report["assessment"];
    EXPECT_TRUE(a["judged"].get<bool>());
    EXPECT_TRUE(a["passed"].get<bool>());
    EXPECT_TRUE(a["within_expert_level"].get<bool>());
    EXPECT_EQ(good.report["record"]["trainee"], "t-01");
    EXPECT_EQ(good.report["record"]["case_id"], "rectum");
    EXPECT_EQ(good.report["record"]["package_sha256"], good.report["package"]["sha256"]);
    EXPECT_EQ(good.report["record"]["player_version"], VISCERA_VERSION_TEXT);
    EXPECT_THAT(metricLine(good.process.out, "clips_on_target"), HasSubstr("2 count (limit ≥ 2) pass"));
    EXPECT_THAT(metricLine(good.process.out, "cut_coverage"), HasSubstr("(limit ≥ 0.8) pass"));

    // The hook's cut 8 mm beside the marked line (and 1 mm lower, on the bent surface).
    const auto aside = editedReplay(replay, dir.path() / "aside.csv", 1, [](double t, std::vector<std::string>& f) {
        if (t >= 1.25 && t <= 2.96) f[3] = add(f[3], 0.0211), f[4] = add(f[4], -0.0027);
        return true;
    });
    const SessionRun cut = run(vcase, aside.string(), 440, dir.path(), "aside");
    EXPECT_THAT(cut.process.out, HasSubstr("verdict       FAIL ("));
    EXPECT_THAT(metricLine(cut.process.out, "cut_outside_edges"),
                ::testing::MatchesRegex(R"(cut_outside_edges [0-9]+ count \(limit ≤ 4\) FAIL)"));
    EXPECT_THAT(metricLine(cut.process.out, "cut_coverage"), HasSubstr("0 fraction (limit ≥ 0.8) FAIL"));
    EXPECT_FALSE(cut.report["assessment"]["passed"].get<bool>());

    // The second clip's approach and squeeze left out: one clip.
    const auto once = editedReplay(replay, dir.path() / "once.csv", 1,
                                   [](double t, std::vector<std::string>&) { return !(t > 5.0 && t < 6.5); });
    const SessionRun one = run(vcase, once.string(), 440, dir.path(), "once");
    EXPECT_THAT(metricLine(one.process.out, "clips_on_target"), HasSubstr("1 count (limit ≥ 2) FAIL"));
    EXPECT_THAT(metricLine(one.process.out, "completion_time_s"), HasSubstr("— s (limit ≤ 9) FAIL"));
    EXPECT_THAT(one.process.out, HasSubstr("verdict       FAIL (completion_time_s, clips_on_target)"));
    // The hook 4.6 mm deeper while it cuts: it burns through the fat to the vessel to protect.
    const auto deep = editedReplay(replay, dir.path() / "deep.csv", 1, [](double t, std::vector<std::string>& f) {
        if (t >= 1.35 && t <= 2.91) f[4] = add(f[4], -0.012);
        return true;
    });
    const SessionRun burn = run(vcase, deep.string(), 440, dir.path(), "deep");
    EXPECT_THAT(metricLine(burn.process.out, "vessel_injury_s"),
                ::testing::MatchesRegex(R"(vessel_injury_s 0\.[0-9]+ s \(limit ≤ 0\.1\) FAIL)"));
    EXPECT_THAT(metricLine(good.process.out, "vessel_injury_s"), HasSubstr("0 s (limit ≤ 0.1) pass"));
    // The page says the same.
    const std::string page = readTextFile(dir.path() / "once" / "session.html");
    EXPECT_THAT(page, HasSubstr("<span class=\"bad\">FAIL</span>"));
    EXPECT_THAT(page, HasSubstr("data-line=\"clips_on_target 1 count (limit ≥ 2) FAIL\""));
}

TEST(AssessmentCase, TheAnastomosisClosesItsGapAndAMissedBiteFails) {
    ScratchDir dir;
    const auto vcase = dir.path() / "anastomosis.vcase";
    ASSERT_EQ(studio({"export", project("anastomosis"), "-o", vcase.string()}).exitCode, 0);
    const std::string replay = project("anastomosis") + "/replays/running-suture.csv";
    const SessionRun good = run(vcase, replay, 2130, dir.path(), "good");
    EXPECT_THAT(good.process.out, HasSubstr("verdict       PASS"));
    EXPECT_THAT(metricLine(good.process.out, "bites"), HasSubstr("13 count (limit ≥ 13) pass"));
    EXPECT_THAT(metricLine(good.process.out, "completion_time_s"), HasSubstr("(limit ≤ 80) pass"));
    EXPECT_NEAR(good.report["suture"]["initial_gap_m"].get<double>(), 0.002, 1e-6);
    for (const auto& m : good.report["assessment"]["metrics"])
        if (m["name"] == "final_gap_m") {
            EXPECT_LT(m["value"].get<double>(), 0.0002) << "the replay closes the gap";
        }
    EXPECT_THAT(metricLine(good.process.out, "final_gap_m"), HasSubstr("(limit ≤ 0.0002) pass"));

    // Stitch 8 (frames 490–559) 4 mm up the needle's axis: the needle misses the walls there, the
    // running suture has 12 bites and a gap between the 7th and the next.
    const double dt = 1.0 / 30;
    const auto missed = editedReplay(replay, dir.path() / "missed.csv", 1, [&](double t, std::vector<std::string>& f) {
        if (t >= 490 * dt - 1e-6 && t < 560 * dt - 1e-6) f[4] = add(f[4], 0.04);
        return true;
    });
    const SessionRun miss = run(vcase, missed.string(), 2130, dir.path(), "missed");
    EXPECT_THAT(metricLine(miss.process.out, "bites"), HasSubstr("12 count (limit ≥ 13) FAIL"));
    EXPECT_THAT(metricLine(miss.process.out, "bite_spacing_error_m"), HasSubstr("(limit ≤ 0.0005) FAIL"));
    EXPECT_THAT(miss.process.out, HasSubstr("verdict       FAIL ("));
    EXPECT_FALSE(miss.report["assessment"]["passed"].get<bool>());
}

namespace {

/// Path and largest force of each tool worked out again from the report's timeline (positions
/// rounded to 1 µm, forces to 0.1 mN there).
void expectToolsAgreeWithTheTimeline(const nlohmann::json& r, const std::string& tag) {
    const nlohmann::json& tools = r["timeline"]["tools"];
    const nlohmann::json& a = r["assessment"]["tools"];
    ASSERT_EQ(tools.size(), a.size()) << tag;
    double total = 0, fmax = 0;
    for (size_t k = 0; k < tools.size(); ++k) {
        double path = 0, f = 0;
        const nlohmann::json& tip = tools[k]["tip_m"];
        for (size_t i = 1; i < tip.size(); ++i) {
            if (tip[i][0].is_null() || tip[i - 1][0].is_null()) continue;
            double d2 = 0;
            for (int c = 0; c < 3; ++c)
                d2 += std::pow(tip[i][c].get<double>() - tip[i - 1][c].get<double>(), 2);
            path += std::sqrt(d2);
        }
        for (const auto& x : tools[k]["force_n"])
            if (!x.is_null()) f = std::max(f, x.get<double>());
        EXPECT_NEAR(a[k]["path_m"].get<double>(), path, 2e-6 * double(tip.size())) << tag << " " << k;
        EXPECT_NEAR(a[k]["force_max_n"].get<double>(), f, 1e-4) << tag << " " << k;
        EXPECT_NEAR(r["metrics"]["tool_path_length_per_tool_m"][k].get<double>(), a[k]["path_m"].get<double>(), 1e-15);
        EXPECT_EQ(r["metrics"]["tool_names"][k], tools[k]["name"]);
        total += a[k]["path_m"].get<double>();
        fmax = std::max(fmax, a[k]["force_max_n"].get<double>());
    }
    EXPECT_NEAR(r["metrics"]["tool_path_length_m"].get<double>(), total, 1e-12) << tag;
    EXPECT_NEAR(r["metrics"]["max_contact_force_n"].get<double>(), fmax, 1e-15) << tag;
    EXPECT_LE(r["metrics"]["mean_contact_force_n"].get<double>(), r["metrics"]["max_contact_force_n"].get<double>())
        << tag << ": one definition (the tissue's force) for both";
}

/// The task counts of the report's blocks against its timeline's events.
void expectCountsAgreeWithTheEvents(const nlohmann::json& r, const std::string& tag) {
    std::map<std::string, int> n;
    for (const auto& e : r["timeline"]["events"])
        n[e["kind"]] += e["kind"] == "cut" || e["kind"] == "puncture" ? e["count"].get<int>() : 1;
    EXPECT_EQ(r["metrics"]["cut_edges"].get<int>(), n["cut"]) << tag;
    EXPECT_EQ(r["metrics"]["clips"].get<int>(), n["clip"]) << tag;
    EXPECT_EQ(r["metrics"]["punctures"].get<int>(), n["puncture"]) << tag;
    if (r.contains("interaction")) {
        const nlohmann::json& d = r["interaction"]["dissection"];
        EXPECT_EQ(d["fascia_edges_cut"].get<int>() + d["fat_edges_cut"].get<int>(), n["cut"]) << tag;
        EXPECT_EQ(r["interaction"]["grasps"].get<int>(), n["grasp"]) << tag;
    }
}

/// The summary's metric lines, the page's rows and the report's metrics: the same figures.
void expectSummaryPageAndReportAgree(const SessionRun& run, const std::filesystem::path& page, const std::string& tag) {
    const std::string html = readTextFile(page);
    std::vector<std::string> rows;
    const std::regex row("data-line=\"([^\"]*)\"");
    for (auto it = std::sregex_iterator(html.begin(), html.end(), row); it != std::sregex_iterator(); ++it)
        rows.push_back((*it)[1].str());
    const nlohmann::json& metrics = run.report["assessment"]["metrics"];
    ASSERT_EQ(rows.size(), metrics.size()) << tag;
    for (size_t i = 0; i < metrics.size(); ++i) {
        const std::string name = metrics[i]["name"];
        EXPECT_EQ(metricLine(run.process.out, name), rows[i]) << tag << ": the summary and the page";
        if (!metrics[i]["value"].is_null())
            EXPECT_FALSE(metrics[i]["value"].get<double>() != metrics[i]["value"].get<double>()) << tag << " " << name;
    }
    // The tools line of the summary and the page's rows.
    for (const auto& t : run.report["assessment"]["tools"]) {
        const std::string name = t["name"];
        const std::regex line(name + " ([^ ;]+) m, ([^ ;)]+) N");
        std::smatch m;
        ASSERT_TRUE(std::regex_search(run.process.out, m, line)) << tag << " " << name;
        EXPECT_THAT(html, HasSubstr("path " + m[1].str() + " m, largest force " + m[2].str() + " N")) << tag;
    }
}

} // namespace

TEST(AssessmentCase, EverySamplesFiguresAgreeAcrossSummaryReportPlotsAndPage) {
    ScratchDir dir;
    struct Sample {
        std::string name, replay;
        int frames;
    };
    const std::vector<Sample> samples = {
        {"tissue-slab", "scripted:press", 120},
        {"organ-blob", "scripted:press", 120},
        {"liver", "replay:" + project("liver") + "/replays/palpation.csv", 240},
        {"rectum", "replay:" + project("rectum") + "/replays/dissection.csv", 440},
        {"anastomosis", "replay:" + project("anastomosis") + "/replays/running-suture.csv", 2130}};
    for (const Sample& s : samples) {
        const auto vcase = dir.path() / (s.name + ".vcase");
        ASSERT_EQ(studio({"export", project(s.name), "-o", vcase.string()}).exitCode, 0) << s.name;
        const auto report = dir.path() / (s.name + ".json");
        const auto plots = dir.path() / s.name;
        SessionRun r{player({"run", vcase.string(), "--headless", "--frames", std::to_string(s.frames), "--device",
                             s.replay, "--report", report.string(), "--plots", plots.string()}),
                     {}};
        ASSERT_EQ(r.process.exitCode, 0) << s.name << ": " << r.process.err << r.process.out;
        r.report = readJsonFile(report);
        expectToolsAgreeWithTheTimeline(r.report, s.name);
        expectCountsAgreeWithTheEvents(r.report, s.name);
        expectSummaryPageAndReportAgree(r, plots / "session.html", s.name);
    }
}
