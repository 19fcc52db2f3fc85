// viscera-results end to end, against SQLite (label unit) or, built with
// VISCERA_RESULTS_TEST_POSTGRES, a real PostgreSQL server (label postgres): the same cases.
#include "player/results/band_pixels.hpp"
#include "player/results/report_generator.hpp"
#include "player/results/results_test_db.hpp"
#include "support/run_process.hpp"
#include "support/scratch_dir.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#ifdef VISCERA_RESULTS_TEST_POSTGRES
#define RESULTS_SUITE ResultsPostgres
#else
#define RESULTS_SUITE ResultsSqlite
#endif

namespace {

namespace fs = std::filesystem;
using viscera::test::ProcessResult;

std::string slurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

size_t count(const std::string& text, const std::string& what) {
    size_t n = 0;
    for (size_t p = text.find(what); p != std::string::npos; p = text.find(what, p + what.size()))
        ++n;
    return n;
}

std::vector<std::string> lines(const std::string& text) {
    std::vector<std::string> out;
    std::istringstream in(text);
    for (std::string l; std::getline(in, l);)
        out.push_back(l);
    return out;
}

class RESULTS_SUITE : public ::testing::Test {
protected:
    void SetUp() override { ASSERT_EQ(db.error(), "") << "the test database could not be made"; }

    ProcessResult results(std::vector<std::string> args) {
        args.push_back("--db");
        args.push_back(db.spec());
        return viscera::test::runProcess(VISCERA_RESULTS_EXE, args);
    }
    /// Adds 10 improving attempts of t01 and 4 of t02 (newest first, to check the ordering).
    void addSessions() {
        auto a = viscera::test::writeReports(scratch.dir, "t01", 10, true);
        auto b = viscera::test::writeReports(scratch.dir, "t02", 4, false);
        std::vector<std::string> args{"add"};
        for (auto it = a.rbegin(); it != a.rend(); ++it)
            args.push_back(it->string());
        for (const auto& p : b)
            args.push_back(p.string());
        const ProcessResult r = results(args);
        ASSERT_EQ(r.exitCode, 0) << r.err;
        ASSERT_EQ(count(r.out, ": added session "), 14u) << r.out;
        reports = a;
    }
    nlohmann::json exported() {
        const ProcessResult r = results({"export", "--format", "json"});
        EXPECT_EQ(r.exitCode, 0) << r.err;
        return nlohmann::json::parse(r.out);
    }

    viscera::test::Scratch scratch{"viscera-results"};
    viscera::test::TestDatabase db{scratch.dir.string()};
    std::vector<fs::path> reports;
};

TEST_F(RESULTS_SUITE, ProgressFindsProficiencyAtAttemptSeven) {
    addSessions();
    const ProcessResult r = results({"progress", "--trainee", "t01", "-o", scratch / "t01"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.out.find("t01 on rectum: 10 attempts, proficient at attempt 7"), std::string::npos) << r.out;
    const ProcessResult s = results({"progress", "--trainee", "t02", "--case", "rectum", "-o", scratch / "t02"});
    ASSERT_EQ(s.exitCode, 0) << s.err;
    EXPECT_NE(s.out.find("not yet proficient (attempt 4 at expert level; one more in a row needed)"), std::string::npos)
        << s.out;
}

TEST_F(RESULTS_SUITE, ProgressWritesTheCurvesAndOnePage) {
    addSessions();
    const fs::path dir = scratch / "curves";
    ASSERT_EQ(results({"progress", "--trainee", "t01", "-o", dir.string()}).exitCode, 0);
    for (const std::string& m : viscera::test::kExpertMetrics) {
        const fs::path png = dir / (m + ".png");
        ASSERT_TRUE(fs::exists(png)) << png;
        EXPECT_GT(fs::file_size(png), 2000u) << png;
        EXPECT_GT(viscera::test::bandPixels(png.string()), 5000) << png << ": the expert band is not drawn";
    }
    EXPECT_FALSE(fs::exists(dir / "force_max_n.png")) << "a metric without an expert level has no curve";
    const std::string page = slurp(dir / "progress.html");
    EXPECT_EQ(count(page, "src=\"data:image/png;base64,"), 3u);
    EXPECT_EQ(count(page, "src=\"http"), 0u);
    EXPECT_NE(page.find("proficient at attempt 7"), std::string::npos);
    for (const std::string& m : viscera::test::kExpertMetrics)
        EXPECT_NE(page.find("alt=\"" + m + "\""), std::string::npos) << m;
}

TEST_F(RESULTS_SUITE, ListNumbersAttemptsInStartOrder) {
    addSessions();
    const ProcessResult r = results({"list", "--trainee", "t01", "--case", "rectum"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto ls = lines(r.out);
    ASSERT_EQ(ls.size(), 11u) << r.out; // header + 10 sessions
    for (int a = 1; a <= 10; ++a) {
        std::istringstream row(ls[a]);
        std::string trainee, caseId, attempt, started, passed, time, unit, expert, proficient;
        row >> trainee >> caseId >> attempt >> started >> passed >> time >> unit >> expert >> proficient;
        EXPECT_EQ(trainee, "t01");
        EXPECT_EQ(attempt, std::to_string(a)) << ls[a];
        EXPECT_EQ(started.substr(0, 10), "2026-11-" + std::string(a < 10 ? "0" : "") + std::to_string(a)) << ls[a];
        EXPECT_EQ(passed, a <= 2 ? "no" : "yes") << ls[a];
        EXPECT_EQ(expert, a >= 6 ? "3/3" : "0/3") << ls[a];
        EXPECT_EQ(proficient, a >= 7 ? "yes" : "no") << ls[a];
    }
    EXPECT_EQ(lines(results({"list"}).out).size(), 15u);
}

TEST_F(RESULTS_SUITE, InstructorSummarizesEveryTrainee) {
    addSessions();
    const fs::path page = scratch.dir / "view" / "instructor.html";
    const ProcessResult r = results({"instructor", "-o", page.string()});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto ls = lines(r.out);
    const auto row = [&](const std::string& t) {
        for (const auto& l : ls)
            if (l.rfind("  " + t + " ", 0) == 0) return l;
        return std::string();
    };
    EXPECT_NE(r.out.find("case rectum"), std::string::npos) << r.out;
    std::istringstream t01(row("t01")), t02(row("t02"));
    std::string name, attempts, passes, best, unit, verdict;
    t01 >> name >> attempts >> passes >> best >> unit;
    EXPECT_EQ(attempts + " " + passes + " " + best, "10 8 10.5") << r.out;
    EXPECT_NE(row("t01").find("at attempt 7"), std::string::npos) << r.out;
    t02 >> name >> attempts >> passes >> best;
    EXPECT_EQ(attempts + " " + passes + " " + best, "4 3 12.0") << r.out;
    EXPECT_NE(row("t02").find("not yet"), std::string::npos) << r.out;
    const std::string html = slurp(page);
    EXPECT_NE(html.find("<h2>Case rectum</h2>"), std::string::npos);
    EXPECT_NE(html.find("<td>t01</td><td>10</td><td>8</td><td>10.5 s</td><td class=\"ok\">at attempt 7</td>"),
              std::string::npos)
        << html;
}

TEST_F(RESULTS_SUITE, ExportGivesEverySessionWithItsMetrics) {
    addSessions();
    const nlohmann::json doc = exported();
    ASSERT_EQ(doc["sessions"].size(), 14u);
    int seen = 0;
    for (const auto& s : doc["sessions"]) {
        ASSERT_EQ(s["metrics"].size(), 4u);
        if (s["trainee"] == "t01" && s["attempt"] == 7) {
            ++seen;
            EXPECT_TRUE(s["proficient"].get<bool>());
            EXPECT_EQ(s["completion_time_s"].get<double>(), 12.0);
            EXPECT_EQ(s["metrics"][1]["value"].get<double>(), 0.9);
            EXPECT_EQ(s["metrics"][2]["expert"]["bound"].get<double>(), 0.9 - 2 * 0.03);
            EXPECT_EQ(s["metrics"][2]["better"], "higher");
            EXPECT_TRUE(s["metrics"][3]["expert"].is_null());
            EXPECT_TRUE(s["metrics"][3]["within_expert"].is_null());
        }
        if (s["trainee"] == "t02" && s["attempt"] == 3) {
            ++seen;
            EXPECT_TRUE(s["completion_time_s"].is_null());
            EXPECT_FALSE(s["passed"].get<bool>());
            EXPECT_TRUE(s["metrics"][0]["value"].is_null());
        }
    }
    EXPECT_EQ(seen, 2);
    const fs::path csv = scratch / "all.csv";
    ASSERT_EQ(results({"export", "-o", csv.string()}).exitCode, 0);
    const auto rows = lines(slurp(csv));
    ASSERT_EQ(rows.size(), 1u + 14 * 4);
    EXPECT_EQ(rows[0].substr(0, 30), "session_id,trainee,case_id,cas");
    EXPECT_EQ(std::count_if(rows.begin(), rows.end(),
                            [](const std::string& l) { return l.find(",t01,rectum,1.2.0,7,") != std::string::npos; }),
              4);
}

TEST_F(RESULTS_SUITE, AddingTheSameReportAgainStoresNothing) {
    addSessions();
    const ProcessResult r = results({"add", reports[6].string(), reports[0].string()});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(count(r.out, "already in the database as session "), 2u) << r.out;
    EXPECT_EQ(exported()["sessions"].size(), 14u);
}

TEST_F(RESULTS_SUITE, MalformedReportIsRefusedNamingTheField) {
    nlohmann::json bad = viscera::test::improvingReport("t09", 1);
    bad["assessment"]["metrics"][1]["better"] = "smaller";
    const fs::path p = scratch / "bad.json";
    std::ofstream(p) << bad.dump();
    const fs::path good = viscera::test::writeReports(scratch.dir, "t09", 1, true)[0];
    ProcessResult r = results({"add", good.string(), p.string()});
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_EQ(r.err,
              "viscera-results: " + p.string() + ": assessment.metrics[1].better: must be \"lower\" or \"higher\"\n");
    bad.erase("record");
    std::ofstream(p) << bad.dump();
    r = results({"add", p.string()});
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.err.find(p.string() + ": record: is missing"), std::string::npos) << r.err;
    EXPECT_EQ(lines(r.err).size(), 1u);
    // Nothing was added: every report is read before any is stored.
    r = results({"list"});
    EXPECT_TRUE(r.exitCode == 2 || r.out == "no sessions\n") << r.out << r.err;
}

TEST_F(RESULTS_SUITE, BadOptionsAndOutputsExitTwo) {
    addSessions();
    EXPECT_EQ(results({"progress", "--trainee", "t01"}).exitCode, 2);
    EXPECT_EQ(results({"progress", "--trainee", "nobody", "-o", scratch / "x"}).exitCode, 2);
    EXPECT_EQ(results({"export", "--format", "xml"}).exitCode, 2);
    EXPECT_EQ(results({"list", "--colour", "red"}).exitCode, 2);
    std::ofstream(scratch / "file") << "x";
    const ProcessResult r = results({"progress", "--trainee", "t01", "-o", scratch / "file"});
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.err.find(scratch / "file"), std::string::npos) << r.err;
}

} // namespace

// Expert levels from expert sessions: t02's four attempts as the experts' (times 30, 12, none,
// 12 s; paths 1.5, 0.9, 1.5, 0.9 m): the mean and the sample standard deviation of each metric
// over the sessions that measured it, as the fragment the studio imports.
TEST_F(RESULTS_SUITE, ExpertLevelsAreTheMeanAndSdOfTheExpertsSessions) {
    addSessions();
    const fs::path out = scratch / "levels.json";
    const ProcessResult r = results({"expert-levels", "--case", "rectum", "--trainee", "t02", "-o", out.string()});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const nlohmann::json doc = nlohmann::json::parse(slurp(out));
    EXPECT_EQ(doc["case_id"], "rectum");
    EXPECT_EQ(doc["sessions"].get<int>(), 4);
    const nlohmann::json& t = doc["metrics"]["completion_time_s"];
    EXPECT_EQ(t["n"].get<int>(), 3) << "the attempt that never met its targets has no time";
    EXPECT_NEAR(t["expert"]["mean"].get<double>(), 18.0, 1e-12);
    EXPECT_NEAR(t["expert"]["sd"].get<double>(), std::sqrt(108.0), 1e-9);
    const nlohmann::json& p = doc["metrics"]["path_length_m"];
    EXPECT_NEAR(p["expert"]["mean"].get<double>(), 1.2, 1e-12);
    EXPECT_NEAR(p["expert"]["sd"].get<double>(), std::sqrt(0.12), 1e-9);
    const ProcessResult both = results({"expert-levels", "--case", "rectum", "--trainee", "t01,t02"});
    ASSERT_EQ(both.exitCode, 0) << both.err;
    const nlohmann::json fromStdout = nlohmann::json::parse(both.out); // JSON alone: redirectable to a file
    EXPECT_EQ(fromStdout["sessions"].get<int>(), 14);
    EXPECT_EQ(results({"expert-levels", "--case", "rectum", "--trainee", "t02,t02"}).exitCode, 2);
    const ProcessResult none = results({"expert-levels", "--case", "rectum", "--trainee", "nobody"});
    EXPECT_EQ(none.exitCode, 2);
    EXPECT_NE(none.err.find("no session of 'nobody' on case 'rectum'"), std::string::npos) << none.err;
}
