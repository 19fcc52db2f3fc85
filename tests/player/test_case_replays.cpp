// Every reference replay of every sample project is a test of its case [issue 57 item 3]: a replay
// kept in projects/<name>/replays/ (the studio's Rehearse dock writes them there) is found here,
// the project exported by viscera-studio and the replay run in lockstep for its length
// (player::replayFrames), as `viscera-player run --device replay:<file>` runs it. The session
// must stay finite and error-free; in a case with an assessment its verdict must be PASS.
#include "haptics/replay_device.hpp"
#include "runtime/report.hpp"
#include "runtime/session.hpp"
#include "support/sample_cli.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

#include <unistd.h>

using namespace viscera;
namespace fs = std::filesystem;

namespace {

struct Replay {
    fs::path project, file;
};

void PrintTo(const Replay& r, std::ostream* os) {
    *os << r.file;
}

std::vector<Replay> committedReplays() {
    std::vector<Replay> out;
    const fs::path projects = fs::path(VISCERA_SOURCE_DIR) / "projects";
    for (const auto& p : fs::directory_iterator(projects)) {
        const fs::path replays = p.path() / "replays";
        if (!fs::is_directory(replays)) continue;
        for (const auto& f : fs::directory_iterator(replays))
            if (f.path().extension() == ".csv") out.push_back({p.path(), f.path()});
    }
    std::sort(out.begin(), out.end(), [](const Replay& a, const Replay& b) { return a.file < b.file; });
    return out;
}

std::string testName(const ::testing::TestParamInfo<Replay>& info) {
    std::string s = info.param.project.filename().string() + "_" + info.param.file.stem().string();
    for (char& c : s)
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
    return s;
}

class CaseReplay : public ::testing::TestWithParam<Replay> {};

} // namespace

TEST(CaseReplays, TheSamplesHaveReplays) {
    EXPECT_GE(committedReplays().size(), 3u) << "liver, rectum and anastomosis keep one each";
}

TEST_P(CaseReplay, RunsToItsVerdict) {
    const Replay& r = GetParam();
    // a folder of this run's own (parallel build trees and runs never share it), gone at the end
    struct Folder {
        fs::path path;
        ~Folder() {
            std::error_code ec;
            fs::remove_all(path, ec);
        }
    } folder{fs::temp_directory_path() /
             ("viscera-case-replay-" + std::to_string(::getpid()) + "-" + testName({r, 0}))};
    fs::create_directories(folder.path);
    const fs::path out = folder.path / "case.vcase";
    const test::ProcessResult exported =
        test::sampleStudio({"export", r.project.string(), "-o", out.string()}); // signed with the sample key
    ASSERT_EQ(exported.exitCode, 0) << exported.err;
    vcase::TrustPolicy trust;
    trust.allowUnsigned = true; // the sample key is not installed here: its signature verifies, untrusted
    trust.now =
        std::chrono::duration_cast<std::chrono::seconds>(std::chrono::system_clock::now().time_since_epoch()).count();
    player::LoadedCase loaded = player::loadCase(out, trust);
    haptics::ReplayDevice device(haptics::Trajectory::load(r.file));
    player::RunOptions o;
    o.frames = player::replayFrames(device.trajectory().duration(), loaded.world->dt());
    o.device = &device;
    o.deviceSpec = "replay:" + r.file.string();
    const player::SessionResult s = player::runSession(loaded, o);
    EXPECT_TRUE(s.ok()) << (s.errors.empty() ? "state not finite" : s.errors.front());
    EXPECT_EQ(static_cast<int>(s.frames.size()), o.frames);
    if (s.assessment.judged)
        EXPECT_TRUE(s.assessment.passed) << r.file << ":\n" << player::assessmentSummary(s.assessment);
}

INSTANTIATE_TEST_SUITE_P(Committed, CaseReplay, ::testing::ValuesIn(committedReplays()), testName);
