// End-to-end: cases built in the test are verified and run by the viscera-player binary; sample
// projects are exported by viscera-studio. Every rejection is checked for its exit code and its
// one-line message naming the file and the rule.
#include "case/case_writer.hpp"
#include "case/zip_craft.hpp"
#include "sim/mesh/generators.hpp"
#include "sim/mesh/tet_io.hpp"
#include "sim/scene/scene.hpp"
#include "sim/util/atomic_file.hpp"
#include "support/case_signing.hpp"
#include "support/run_process.hpp"
#include "support/slab_case.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>
#include <thread>

using namespace viscera;
using ::testing::HasSubstr;
using ::testing::Not;
namespace fs = std::filesystem;
using vcase::test::RawEntry;
using vcase::test::ScratchDir;

namespace {

test::ProcessResult player(const std::vector<std::string>& args) {
    return test::runProcess(VISCERA_PLAYER_EXE, test::trustingSampleKey(args));
}
test::ProcessResult studio(const std::vector<std::string>& args) {
    return test::runProcess(VISCERA_STUDIO_EXE, test::signingWithSampleKey(args));
}

int lineCount(const std::string& s) {
    return static_cast<int>(std::count(s.begin(), s.end(), '\n'));
}

/// The slab case (slab_case.hpp) with the given features, signed with the sample key.
std::string writeSlabCase(const ScratchDir& dir, const std::string& name, std::vector<std::string> features,
                          sim::Vec3 gravity = sim::Vec3(0, 0, -9.81), const std::string& render = "") {
    test::SlabCase slab;
    slab.features = std::move(features);
    slab.gravity = gravity;
    slab.render = render;
    return test::writeSlabCase(dir.path() / name, slab).string();
}

nlohmann::json readJson(const std::filesystem::path& p) {
    std::ifstream in(p);
    return nlohmann::json::parse(in);
}

struct Rejection {
    const char* label;
    std::string bytes;
    const char* rule;
};

} // namespace

TEST(PlayerCli, VerifyRejectsEachBrokenPackageWithADistinctMessage) {
    ScratchDir dir;
    const std::vector<RawEntry> good = {{"meshes/a.vtet", vcase::test::unitTetVtet()}};
    std::vector<Rejection> cases;
    {
        auto files = good;
        vcase::Manifest m = vcase::test::manifestFor(files);
        files[0].bytes[files[0].bytes.size() - 2] ^= 1; // same size, different hash
        cases.push_back({"hash", vcase::test::craftPackage(m, files), "sha256 mismatch"});
    }
    {
        auto files = good;
        vcase::Manifest m = vcase::test::manifestFor(files);
        files.push_back({"extra.txt", "surprise"});
        cases.push_back({"unlisted", vcase::test::craftPackage(m, files), "not listed in manifest.json"});
    }
    {
        auto files = good;
        vcase::Manifest m = vcase::test::manifestFor(files);
        files.push_back({"../x", "escape"});
        cases.push_back({"dotdot", vcase::test::craftPackage(m, files), "'..'"});
    }
    {
        auto files = good;
        vcase::Manifest m = vcase::test::manifestFor(files);
        files.push_back({"/etc/passwd", "root"});
        cases.push_back({"absolute", vcase::test::craftPackage(m, files), "absolute entry path"});
    }
    {
        vcase::Manifest m = vcase::test::manifestFor(good);
        m.schemaVersion = 99;
        cases.push_back({"schema", vcase::test::craftPackage(m, good), "schemaVersion 99 is newer"});
    }
    {
        std::string whole = vcase::test::craftPackage(vcase::test::manifestFor(good), good);
        cases.push_back({"truncated", whole.substr(0, whole.size() / 2), "not a valid zip archive"});
    }
    std::set<std::string> messages;
    for (const auto& c : cases) {
        const auto path = dir.write(std::string(c.label) + ".vcase", c.bytes);
        // Unsigned: admitted only with --allow-unsigned, so that the package rules after the
        // admission (digests, listing, compatibility) are reached at all.
        test::ProcessResult r = player({"verify", path.string(), "--allow-unsigned"});
        EXPECT_EQ(r.exitCode, 1) << c.label << ": " << r.err;
        EXPECT_THAT(r.err, HasSubstr(c.rule)) << c.label;
        EXPECT_THAT(r.err, HasSubstr(path.string())) << c.label;
        EXPECT_EQ(lineCount(r.err), 1) << c.label << ": " << r.err;
        messages.insert(r.err.substr(r.err.find(path.filename().string()) + path.filename().string().size()));
    }
    EXPECT_EQ(messages.size(), cases.size()) << "every rule has its own message";
}

TEST(PlayerCli, VerifyAcceptsAGoodCase) {
    ScratchDir dir;
    const auto path = writeSlabCase(dir, "slab.vcase", {"gravity", "xpbd"});
    test::ProcessResult r = player({"verify", path});
    EXPECT_EQ(r.exitCode, 0) << r.err;
    EXPECT_THAT(r.out, HasSubstr("ok (case slab-test 1.0.0"));
}

TEST(PlayerCli, RunWritesTheSessionReport) {
    ScratchDir dir;
    const auto path = writeSlabCase(dir, "slab.vcase", {"gravity", "xpbd"});
    const auto report = dir.path() / "report.json";
    test::ProcessResult r = player({"run", path, "--headless", "--frames", "60", "--report", report.string()});
    ASSERT_EQ(r.exitCode, 0) << r.err << r.out;
    EXPECT_THAT(r.out, HasSubstr("subsystems    gravity, xpbd"));
    EXPECT_THAT(r.out, HasSubstr(report.string()));
    nlohmann::json j = readJson(report);
    EXPECT_EQ(j["case"]["id"], "slab-test");
    EXPECT_EQ(j["case"]["version"], "1.0.0");
    EXPECT_EQ(j["active_subsystems"], nlohmann::json({"gravity", "xpbd"}));
    ASSERT_EQ(j["frames"].size(), 60u);
    for (const auto& f : j["frames"]) {
        EXPECT_EQ(f["substeps"], 50);
        EXPECT_EQ(f["iterations"], 1);
        EXPECT_GE(f["step_ms"].get<double>(), 0.0);
    }
    EXPECT_TRUE(j["accuracy"].is_array());
    EXPECT_TRUE(j["invariants"]["all_finite"].get<bool>());
    EXPECT_GT(j["invariants"]["max_step_displacement_m"].get<double>(), 0.0);
    EXPECT_EQ(j["invariants"]["max_force_n"].get<double>(), 0.0);
    // The free end sags under gravity by a plausible amount (millimetres, not metres).
    const double sag = j["metrics"]["final_node_displacement_m"].get<double>();
    EXPECT_GT(sag, 1e-4);
    EXPECT_LT(sag, 0.05);
    EXPECT_GE(j["metrics"]["max_node_displacement_m"].get<double>(), sag) << "the largest is over the run";
    EXPECT_EQ(j["schemaVersion"].get<int>(), 5);
    EXPECT_TRUE(j["errors"].empty());
    EXPECT_TRUE(j["warnings"].empty());
    EXPECT_THAT(r.out, HasSubstr("displacement  largest node distance from rest"));
    EXPECT_THAT(r.out, HasSubstr("(elastic + kinetic + gravitational, measured from the rest pose)"));
}

TEST(PlayerCli, UnwritableOutputsAreRefusedBeforeTheFirstFrame) {
    ScratchDir dir;
    const auto path = writeSlabCase(dir, "slab.vcase", {"gravity", "xpbd"});
    const fs::path file = dir.path() / "a-file";
    writeFileAtomic(file, "x");
    const fs::path folder = dir.path() / "reports";
    fs::create_directories(folder);
    const struct {
        std::vector<std::string> args;
        std::string message;
    } cases[] = {
        {{"--report", (file / "r.json").string()},
         (file / "r.json").string() + ": cannot write the report ('" + file.string() + "' is a file, not a folder)"},
        {{"--report", folder.string()}, folder.string() + ": cannot write the report (it is a folder)"},
        {{"--screenshot", (file / "s.png").string()},
         (file / "s.png").string() + ": cannot write the screenshot ('" + file.string() + "' is a file, not a folder)"},
        {{"--device", "scripted:press", "--trace", folder.string()},
         folder.string() + ": cannot write the trace (it is a folder)"},
        {{"--plots", file.string()}, file.string() + ": the output folder is a file, not a folder"},
    };
    for (const auto& c : cases) {
        std::vector<std::string> args = {"run", path, "--headless", "--frames", "600"};
        args.insert(args.end(), c.args.begin(), c.args.end());
        const test::ProcessResult r = player(args);
        EXPECT_EQ(r.exitCode, 1) << r.err;
        EXPECT_EQ(r.err, "viscera-player: " + c.message + "\n");
        EXPECT_THAT(r.err, Not(HasSubstr("frame"))); // no frame ran
        EXPECT_TRUE(r.out.empty()) << r.out;
    }
    // A folder that does not exist yet is made, as writing the report would.
    const fs::path fresh = dir.path() / "new" / "r.json";
    const test::ProcessResult ok = player({"run", path, "--headless", "--frames", "2", "--report", fresh.string()});
    EXPECT_EQ(ok.exitCode, 0) << ok.err;
    EXPECT_TRUE(fs::exists(fresh));
    // As root, permissions do not stop a write: the unwritable folder is checked only as a user.
    if (::geteuid() != 0) {
        const fs::path locked = dir.path() / "locked";
        fs::create_directories(locked);
        fs::permissions(locked, fs::perms::owner_read | fs::perms::owner_exec);
        const test::ProcessResult r = player({"run", path, "--headless", "--report", (locked / "r.json").string()});
        EXPECT_EQ(r.exitCode, 1);
        EXPECT_THAT(r.err, HasSubstr("takes no new file"));
        fs::permissions(locked, fs::perms::owner_all);
    }
}

TEST(PlayerCli, OutputsOverAnInputAreRefusedBeforeTheFirstFrame) {
    ScratchDir dir;
    const auto path = writeSlabCase(dir, "slab.vcase", {"gravity", "xpbd"});
    const std::string before = readFile(path);
    const fs::path alias = dir.path() / "alias.vcase", replay = dir.path() / "press.csv";
    fs::create_symlink(path, alias);
    writeFileAtomic(replay, "not read: refused before the device opens");
    const struct {
        std::vector<std::string> args;
        std::string message;
    } cases[] = {
        {{"--report", path}, path + ": cannot write the report over the input '" + path + "'"},
        {{"--screenshot", alias.string()},
         alias.string() + ": cannot write the screenshot over the input '" + path + "'"},
        {{"--device", "replay:" + replay.string(), "--trace", replay.string()},
         replay.string() + ": cannot write the trace over the input '" + replay.string() + "'"},
    };
    for (const auto& c : cases) {
        std::vector<std::string> args = {"run", path, "--headless", "--frames", "60"};
        args.insert(args.end(), c.args.begin(), c.args.end());
        const test::ProcessResult r = player(args);
        EXPECT_EQ(r.exitCode, 1) << r.err;
        EXPECT_EQ(r.err, "viscera-player: " + c.message + "\n");
        EXPECT_TRUE(r.out.empty()) << r.out;
    }
    EXPECT_EQ(readFile(path), before) << "the case is intact";
}

TEST(PlayerCli, AReportThatCannotBeWrittenAtTheEndKeepsTheSummaryAndIsSavedElsewhere) {
    // The report's folder takes files when the run starts; at the end its name has become a folder
    // (as a full disk, the write fails). The summary is printed, the report saved in TMPDIR.
    ScratchDir dir;
    const auto path = writeSlabCase(dir, "slab.vcase", {"gravity", "xpbd"});
    const fs::path out = dir.path() / "out" / "r.json", tmp = dir.path() / "tmp", log = dir.path() / "player";
    fs::create_directories(out.parent_path());
    fs::create_directories(tmp);
    const char* oldTmp = std::getenv("TMPDIR");
    const std::string savedTmp = oldTmp ? oldTmp : "";
    ::setenv("TMPDIR", tmp.c_str(), 1);
    // Real time with a device: the 240 frames take 4 s of wall clock whatever this machine's speed.
    test::Background run(VISCERA_PLAYER_EXE,
                         test::trustingSampleKey({"run", path, "--headless", "--realtime", "--device", "scripted:press",
                                                  "--frames", "240", "--report", out.string()}),
                         log.string());
    if (oldTmp)
        ::setenv("TMPDIR", savedTmp.c_str(), 1);
    else
        ::unsetenv("TMPDIR");
    ASSERT_GT(run.pid, 0);
    // Past the checks: the first progress line (frame 24 of 240) is on stderr.
    bool running = false;
    for (int k = 0; k < 600 && !running; ++k) {
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
        running = fs::exists(log.string() + ".err") &&
                  readFile(log.string() + ".err").find("frame 24/240") != std::string::npos;
    }
    ASSERT_TRUE(running) << readFile(log.string() + ".err");
    fs::create_directories(out / "in-the-way");
    EXPECT_EQ(run.waitFor(), 1);
    const std::string stdoutText = readFile(log.string() + ".out"), err = readFile(log.string() + ".err");
    EXPECT_THAT(stdoutText, HasSubstr("status        ok"));
    EXPECT_THAT(err, HasSubstr(out.string() + ": rename from temporary file failed: "));
    EXPECT_THAT(err, HasSubstr("; the report was saved to " + tmp.string() + "/viscera-report-"));
    std::vector<fs::path> saved;
    for (const auto& e : fs::directory_iterator(tmp))
        saved.push_back(e.path());
    ASSERT_EQ(saved.size(), 1u) << "the report, and no temporary left behind";
    EXPECT_THAT(stdoutText, HasSubstr("report        " + saved[0].string()));
    const auto report = nlohmann::json::parse(readFile(saved[0]));
    EXPECT_EQ(report["frames"].size(), 240u);
}

TEST(PlayerCli, ATitleThatCouldRewriteTheSummaryIsRefused) {
    // A title with a newline and an erase-line escape would print a fake "status ok" over a failed
    // session's summary: the case writer refuses it, and a crafted package is refused by verify and
    // run, one line naming the field.
    ScratchDir dir;
    auto mesh = sim::makeBoxTetMesh({sim::Vec3::Zero(), sim::Vec3(0.08, 0.02, 0.02), {8, 2, 2}});
    sim::SceneDesc scene;
    scene.xpbd.substeps = 50;
    sim::BodyDesc body;
    body.name = "slab";
    body.meshPath = "meshes/slab.vtet";
    body.fixedNodes = {0, 1, 2};
    scene.bodies.push_back(body);
    const std::vector<RawEntry> files{{"scene.json", sim::formatScene(scene)},
                                      {"meshes/slab.vtet", sim::formatVtet(*mesh)}};
    vcase::Manifest header = vcase::test::manifestFor(files);
    header.features = {"gravity", "xpbd"};
    header.title = "Slab\n\x1b[2Kstatus        ok";
    EXPECT_THROW(vcase::CaseWriter{header}, std::exception) << "the writer takes the reader's rule";
    const std::string path = dir.write("title.vcase", vcase::test::craftPackage(header, files)).string();
    for (const std::vector<std::string>& args :
         {std::vector<std::string>{"verify", path},
          std::vector<std::string>{"run", path, "--headless", "--frames", "2"}}) {
        const test::ProcessResult r = player(args);
        EXPECT_EQ(r.exitCode, 1) << r.err;
        EXPECT_EQ(r.err, "viscera-player: " + path +
                             ": manifest.json: title: must be printable text: control character U+000A at byte 4\n");
        EXPECT_TRUE(r.out.empty()) << r.out;
    }
}

TEST(PlayerCli, OnlyDeclaredSubsystemsRun) {
    ScratchDir dir;
    // Without gravity the world creates no gravity subsystem and nothing moves.
    const auto path = writeSlabCase(dir, "still.vcase", {"xpbd"}, sim::Vec3::Zero());
    const auto report = dir.path() / "r.json";
    test::ProcessResult r = player({"run", path, "--headless", "--frames", "10", "--report", report.string()});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    nlohmann::json j = readJson(report);
    EXPECT_EQ(j["active_subsystems"], nlohmann::json({"xpbd"}));
    EXPECT_LT(j["metrics"]["max_node_displacement_m"].get<double>(), 1e-12);
}

TEST(PlayerCli, RunRejectsUnsupportedOrUndeclaredFeatures) {
    ScratchDir dir;
    // ("needle" and "clip" became supported features with the suturing and tool engines.)
    auto a = player({"run", writeSlabCase(dir, "laser.vcase", {"gravity", "laser", "xpbd"}), "--headless"});
    EXPECT_EQ(a.exitCode, 1);
    EXPECT_THAT(a.err, HasSubstr("features: 'laser' is not supported by this player"));
    // A declared feature the scene does not use creates nothing.
    const auto report = dir.path() / "clip.json";
    auto c = player({"run", writeSlabCase(dir, "clip.vcase", {"clip", "gravity", "xpbd"}), "--headless", "--frames",
                     "2", "--report", report.string()});
    ASSERT_EQ(c.exitCode, 0) << c.err;
    EXPECT_EQ(readJson(report)["active_subsystems"], nlohmann::json({"gravity", "xpbd"}));
    auto b = player({"run", writeSlabCase(dir, "nograv.vcase", {"xpbd"}), "--headless"});
    EXPECT_EQ(b.exitCode, 1);
    EXPECT_THAT(b.err, HasSubstr("the scene sets gravity but the manifest does not declare 'gravity'"));
}

TEST(PlayerCli, RunRejectsAMalformedRenderBlockAtLoad) {
    ScratchDir dir;
    const auto bad =
        writeSlabCase(dir, "bad.vcase", {"gravity", "xpbd"}, sim::Vec3(0, 0, -9.81), R"({"post": {"bloom": true}})");
    auto r = player({"run", bad, "--headless", "--frames", "5"});
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_THAT(r.err, HasSubstr("bad.vcase:scene.json: render.post.bloom: unknown field"));
    EXPECT_EQ(lineCount(r.err), 1) << r.err;
    const auto good = writeSlabCase(dir, "good.vcase", {"gravity", "xpbd"}, sim::Vec3(0, 0, -9.81),
                                    R"({"sss": false, "post": {"tone_mapping": false}})");
    EXPECT_EQ(player({"run", good, "--headless", "--frames", "5"}).exitCode, 0);
}

TEST(PlayerCli, UsageErrorsAreClear) {
    EXPECT_EQ(player({}).exitCode, 2);
    auto r = player({"run", "x.vcase", "--frames", "abc", "--headless"});
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_THAT(r.err, HasSubstr("--frames 'abc' must be an integer"));
    auto m = player({"verify", "/nonexistent/case.vcase"});
    EXPECT_EQ(m.exitCode, 1);
    EXPECT_THAT(m.err, HasSubstr("/nonexistent/case.vcase"));
    auto ls = player({"run", "x.vcase", "--headless", "--lockstep", "--device", "console:127.0.0.1:7400"});
    EXPECT_EQ(ls.exitCode, 2);
    EXPECT_THAT(ls.err, HasSubstr("--lockstep: --device console:127.0.0.1:7400 runs on the wall clock"));
    EXPECT_EQ(player({"run", "x.vcase", "--headless", "--lockstep", "--realtime"}).exitCode, 2);
    // --help on every subcommand, anywhere after it: its own usage on stdout, exit 0, nothing run.
    for (const auto& [args, line] : std::vector<std::pair<std::vector<std::string>, std::string>>{
             {{"run", "--help"}, "usage: viscera-player run <case.vcase> [options]"},
             {{"run", "/nonexistent.vcase", "--headless", "-h"}, "--screenshot FILE.png"},
             {{"verify", "--help"}, "usage: viscera-player verify <case.vcase>"},
             {{"plot", "--help"}, "usage: viscera-player plot <report.json> -o DIR"}}) {
        auto h = player(args);
        EXPECT_EQ(h.exitCode, 0) << args[0];
        EXPECT_THAT(h.out, HasSubstr(line));
        EXPECT_TRUE(h.err.empty()) << h.err;
    }
    for (const auto& [sub, line] :
         std::vector<std::pair<std::string, std::string>>{{"export", "usage: viscera-studio export"},
                                                          {"import", "usage: viscera-studio import"},
                                                          {"open", "usage: viscera-studio open"},
                                                          {"texture", "usage: viscera-studio texture"},
                                                          {"replay", "usage: viscera-studio replay"}}) {
        auto h = test::runProcess(VISCERA_STUDIO_EXE, {sub, "--help"});
        EXPECT_EQ(h.exitCode, 0) << sub;
        EXPECT_THAT(h.out, HasSubstr(line));
    }
}

TEST(PlayerCli, ADeviceThatDrivesNoToolIsWarnedAbout) {
    ScratchDir dir;
    const auto path = writeSlabCase(dir, "slab.vcase", {"gravity", "xpbd"});
    const auto report = dir.path() / "report.json";
    auto r = player(
        {"run", path, "--headless", "--frames", "20", "--device", "scripted:press", "--report", report.string()});
    ASSERT_EQ(r.exitCode, 0) << r.err << r.out;
    EXPECT_THAT(r.err, HasSubstr("--device scripted:press: the case declares no tool a device can drive"));
    EXPECT_THAT(r.out, HasSubstr("warning       --device scripted:press: the case declares no tool"));
    const nlohmann::json j = readJson(report);
    ASSERT_EQ(j["warnings"].size(), 1u);
    EXPECT_TRUE(j["haptics"]["tools"].empty());
    EXPECT_EQ(j["metrics"]["device_max_force_n"].get<double>(), 0.0);
}

TEST(StudioCli, ExportsAndThePlayerRunsTheSampleProject) {
    ScratchDir dir;
    const auto out = dir.path() / "tissue-slab.vcase";
    auto e = studio({"export", std::string(VISCERA_SOURCE_DIR) + "/projects/tissue-slab", "-o", out.string()});
    ASSERT_EQ(e.exitCode, 0) << e.err;
    EXPECT_THAT(e.out, HasSubstr("body slab:"));
    EXPECT_THAT(e.out, HasSubstr("features: gravity xpbd"));
    auto v = player({"verify", out.string()});
    EXPECT_EQ(v.exitCode, 0) << v.err;
    const auto report = dir.path() / "r.json";
    auto r = player({"run", out.string(), "--headless", "--frames", "30", "--report", report.string()});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_TRUE(readJson(report)["invariants"]["all_finite"].get<bool>());
    // Exports are deterministic.
    const auto again = dir.path() / "again.vcase";
    ASSERT_EQ(
        studio({"export", std::string(VISCERA_SOURCE_DIR) + "/projects/tissue-slab", "-o", again.string()}).exitCode,
        0);
    std::ifstream a(out, std::ios::binary), b(again, std::ios::binary);
    std::string sa((std::istreambuf_iterator<char>(a)), {}), sb((std::istreambuf_iterator<char>(b)), {});
    EXPECT_EQ(sa, sb);
}

TEST(StudioCli, ImportRejectsBadMeshesWithOneLineErrors) {
    ScratchDir dir;
    struct Bad {
        const char* name;
        std::string text;
        const char* rule;
    };
    const std::vector<Bad> bad = {
        {"nan.obj", "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n", "non-finite"},
        {"nofaces.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n", "no faces"},
        {"range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n", "out of range"},
        {"mesh.xyz", "0 0 0\n1 0 0\n", "unsupported format"},
    };
    for (const auto& b : bad) {
        const auto path = dir.write(b.name, b.text);
        auto r = studio({"import", path.string()});
        EXPECT_EQ(r.exitCode, 1) << b.name << ": " << r.err;
        EXPECT_THAT(r.err, HasSubstr(b.name));
        EXPECT_THAT(r.err, HasSubstr(b.rule)) << r.err;
        EXPECT_EQ(lineCount(r.err), 1) << r.err;
    }
    auto bp = dir.write("project.json", R"({"schemaVersion": 1, "caseId": "x", "caseVersion": "1.0.0",
        "solver": {"type": "xpbd"}, "bodies": [{"name": "b", "mesh": {"generator": "box", "size": [1, 1, -1],
        "cells": [1, 1, 1]}, "material": {"model": "stable_neo_hookean", "youngs_modulus": 1e4, "poisson_ratio": 0.4,
        "density": 1000}}]})");
    auto r = studio({"export", dir.path().string(), "-o", (dir.path() / "x.vcase").string()});
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_THAT(r.err, HasSubstr("project.json: bodies[0].mesh.size: every edge length must be positive"));
    EXPECT_FALSE(std::filesystem::exists(dir.path() / "x.vcase"));
}

TEST(PlayerCli, PlotDrawsAReportAndRefusesABrokenOne) {
    ScratchDir dir;
    const auto path = writeSlabCase(dir, "slab.vcase", {"gravity", "xpbd"});
    const auto report = dir.path() / "r.json";
    ASSERT_EQ(player({"run", path, "--headless", "--frames", "30", "--report", report.string()}).exitCode, 0);
    const fs::path out = dir.path() / "plots";
    const test::ProcessResult r = player({"plot", report.string(), "-o", out.string()});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    for (const char* f :
         {"step_time.png", "forces.png", "tool_paths.png", "events.png", "stability.png", "session.html"}) {
        EXPECT_TRUE(fs::exists(out / f)) << f;
        EXPECT_THAT(r.out, HasSubstr((out / f).string()));
    }
    EXPECT_TRUE(r.err.empty()) << r.err;
    // A broken report: one line naming the file and the field; no folder made.
    nlohmann::json j = readJson(report);
    j["frames"][2]["step_ms"] = "slow";
    const fs::path bad = dir.path() / "bad.json";
    writeFileAtomic(bad, j.dump());
    const fs::path none = dir.path() / "none";
    const test::ProcessResult b = player({"plot", bad.string(), "-o", none.string()});
    EXPECT_EQ(b.exitCode, 1);
    EXPECT_EQ(b.err, "viscera-player: " + bad.string() + ": frames[2].step_ms: must be a number\n");
    EXPECT_FALSE(fs::exists(none));
    const test::ProcessResult m = player({"plot", (dir.path() / "missing.json").string(), "-o", none.string()});
    EXPECT_EQ(m.exitCode, 1);
    EXPECT_THAT(m.err, HasSubstr("missing.json: cannot open for reading"));
    EXPECT_EQ(player({"plot", report.string()}).exitCode, 2) << "no -o";
}

TEST(PlayerCli, SoakRunsCasesBackToBackAndReportsEachInterval) {
    ScratchDir dir;
    const auto path = writeSlabCase(dir, "slab.vcase", {"gravity", "xpbd"});
    const auto report = dir.path() / "soak.json";
    const test::ProcessResult r = player({"soak", path, path, "--minutes", "0.05", "--line-seconds", "1", "--frames",
                                          "20", "--report", report.string()});
    ASSERT_EQ(r.exitCode, 0) << r.err << r.out;
    EXPECT_THAT(r.out, HasSubstr("line   1"));
    EXPECT_THAT(r.out, HasSubstr("finite yes"));
    EXPECT_THAT(r.out, HasSubstr("; ok"));
    const nlohmann::json j = readJson(report);
    ASSERT_GE(j["lines"].size(), 2u) << "3 s at a line a second";
    int64_t frames = 0;
    for (const auto& l : j["lines"]) {
        EXPECT_TRUE(l["all_finite"].get<bool>());
        EXPECT_TRUE(l["energy_bounded"].get<bool>());
        EXPECT_GT(l["rss_mib"].get<double>(), 1.0);
        frames += l["frames"].get<int64_t>();
    }
    EXPECT_EQ(frames, j["frames"].get<int64_t>());
    EXPECT_GE(j["passes"].get<int>(), 2) << "both cases ran";
    EXPECT_TRUE(j["errors"].empty());
    // Refused before any time is spent: a missing case, a wall-clock device, a bad number.
    const test::ProcessResult m = player({"soak", path, (dir.path() / "missing.vcase").string(), "--minutes", "1"});
    EXPECT_EQ(m.exitCode, 1);
    EXPECT_THAT(m.err, HasSubstr("missing.vcase"));
    EXPECT_THAT(m.out, Not(HasSubstr("line")));
    const test::ProcessResult c = player({"soak", path + "@console:127.0.0.1:7400", "--minutes", "1"});
    EXPECT_EQ(c.exitCode, 1);
    EXPECT_THAT(c.err, HasSubstr("the soak steps devices with the physics"));
    EXPECT_EQ(player({"soak", path, "--minutes", "abc"}).exitCode, 2);
    const test::ProcessResult over = player({"soak", path, "--minutes", "1", "--report", path});
    EXPECT_EQ(over.exitCode, 1);
    EXPECT_EQ(over.err, "viscera-player: " + path + ": cannot write the soak report over the input '" + path + "'\n");
}
