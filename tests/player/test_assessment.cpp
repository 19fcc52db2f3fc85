// A session's assessment [issue 41]: the block's rules in the one scene reader, every metric
// against a figure worked out by hand on a synthetic timeline (paths, idle time, collisions,
// field of view, forces, cut coverage and cuts outside, clips on and off target, bites), limits
// and expert levels judged on the right side, and the figures' formatting.
#include "runtime/assessment.hpp"
#include "runtime/report.hpp"
#include "runtime/session.hpp"
#include "sim/scene/scene.hpp"
#include "sim/util/error.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numbers>

using namespace viscera;
using ::testing::HasSubstr;
using Vec3 = Eigen::Vector3d;

namespace {

constexpr const char* kSceneHead = R"({"solver": {"type": "xpbd", "dt": 0.01},
  "bodies": [{"name": "b", "mesh": "b.tet", "material": {"model": "linear", "youngs_modulus": 1000, "poisson_ratio": 0.3, "density": 1000}}],)";

sim::SceneDesc sceneWith(const std::string& assessment) {
    return sim::parseScene(std::string(kSceneHead) + R"("assessment": )" + assessment + "}", "scene.json");
}

std::string refusal(const std::string& assessment) {
    try {
        sceneWith(assessment);
    } catch (const InputError& e) {
        return e.what();
    }
    return "(accepted)";
}

/// A timeline sampled every 0.1 s over `n` samples with the given tools.
player::SessionResult timeline(size_t n, std::vector<player::SessionTimeline::Tool> tools) {
    player::SessionResult r;
    r.frameDt = 0.1;
    for (size_t i = 0; i < n; ++i)
        r.timeline.t_s.push_back(0.1 * double(i + 1));
    r.timeline.tools = std::move(tools);
    r.simTime = 0.1 * double(n);
    return r;
}

/// A tool moving along +x at `speed` m/s for the first `moving` samples of n, then still; force f.
player::SessionTimeline::Tool mover(const std::string& name, const std::string& hand, size_t n, size_t moving,
                                    double speed, double force, Vec3 start = Vec3::Zero()) {
    player::SessionTimeline::Tool t{name, "grasper", hand, 0.002, 0.0, {}, {}, {}};
    Vec3 p = start;
    for (size_t i = 0; i < n; ++i) {
        if (i > 0 && i < moving) p.x() += speed * 0.1;
        t.tip.push_back(p);
        t.force_n.push_back(force);
    }
    return t;
}

} // namespace

TEST(Assessment, TheBlockIsReadAndWrittenByTheOneSceneReader) {
    const sim::SceneDesc s = sceneWith(R"({"targets": {
        "cut": [{"line": [[0,0,0],[0.05,0,0]], "radius": 0.004, "coverage": 0.8}],
        "clip": [{"position": [0.01,0,0], "tolerance": 0.005, "count": 2}],
        "suture": {"plane": {"point": [0,0,0], "normal": [0,0,2]}, "bites": 3, "depth": [0.001, 0.005], "spacing": [0.001, 0.003], "max_gap": 0.0002}},
      "force_threshold_n": 2, "reference_path_m": 0.3,
      "metrics": {"cut_coverage": {"limit": 0.5}, "completion_time_s": {"limit": 9, "expert": {"mean": 5, "sd": 1}}}})");
    ASSERT_TRUE(s.assessment);
    const sim::AssessmentDesc& a = *s.assessment;
    ASSERT_EQ(a.cuts.size(), 1u);
    EXPECT_DOUBLE_EQ(a.cuts[0].coverage, 0.8);
    EXPECT_EQ(a.clips[0].count, 2);
    EXPECT_DOUBLE_EQ(a.suture->planeNormal.z(), 1.0) << "normalized";
    EXPECT_DOUBLE_EQ(a.forceThresholdN, 2.0);
    ASSERT_EQ(a.metrics.size(), 2u);
    EXPECT_EQ(a.metrics[0].name, "completion_time_s") << "catalogue order";
    const sim::SceneDesc back = sim::parseScene(sim::formatScene(s), "scene.json");
    ASSERT_TRUE(back.assessment);
    EXPECT_EQ(sim::formatScene(back), sim::formatScene(s)) << "what the writer writes, the reader reads";
}

TEST(Assessment, AMalformedBlockIsRefusedNamingTheFieldAndTheRule) {
    EXPECT_THAT(refusal(R"({"metrics": {"speed": {"limit": 1}}})"),
                HasSubstr("scene.json: assessment.metrics.speed: is not a metric the player measures"));
    EXPECT_THAT(refusal(R"({"metrics": {"path_length_m": {}}})"),
                HasSubstr("assessment.metrics.path_length_m: needs a limit, an expert level or both"));
    EXPECT_THAT(refusal(R"({"metrics": {"path_length_m": {"expert": {"mean": 1, "sd": -1}}}})"),
                HasSubstr("assessment.metrics.path_length_m.expert.sd"));
    EXPECT_THAT(refusal(R"({"targets": {"cut": [{"line": [[0,0,0]]}]}})"), HasSubstr("assessment.targets.cut[0].line"));
    EXPECT_THAT(refusal(R"({"targets": {"cut": [{"line": [[0,0,0],[0,0,0]]}]}})"),
                HasSubstr("must be at least 0.1 mm long"));
    EXPECT_THAT(refusal(R"({"targets": {"clip": [{"position": [0,0,0], "count": 0}]}})"),
                HasSubstr("assessment.targets.clip[0].count"));
    EXPECT_THAT(refusal(R"({"targets": {"suture": {"plane": {"point": [0,0,0], "normal": [0,0,0]}}}})"),
                HasSubstr("assessment.targets.suture.plane.normal: must not be zero"));
    EXPECT_THAT(
        refusal(
            R"({"targets": {"suture": {"plane": {"point": [0,0,0], "normal": [0,0,1]}, "depth": [0.005, 0.001]}}})"),
        HasSubstr("assessment.targets.suture.depth: must be [min, max] with min < max"));
    EXPECT_THAT(refusal(R"({"force_threshold_n": "high"})"), HasSubstr("assessment.force_threshold_n"));
    EXPECT_THAT(refusal(R"({"grade": 1})"), HasSubstr("assessment.grade: unknown field"));
}

// Two tools for 3 s: the left moves 20 mm/s for 1 s then stops; the right moves 10 mm/s for
// 2 s. Paths 18 mm and 19 mm (one sample's step short of the whole: the first sample is the
// start); idle from 2.0 s on; the forces 0.5 N and 2 N against a 1.5 N threshold.
TEST(Assessment, MotionAndForceFiguresAreThoseWorkedOutByHand) {
    player::SessionResult r = timeline(30, {mover("left", "left", 30, 10, 0.02, 0.5, Vec3(0, 0.1, 0)),
                                            mover("right", "right", 30, 20, 0.01, 2.0, Vec3(0, -0.1, 0))});
    sim::AssessmentDesc desc;
    desc.forceThresholdN = 1.5;
    desc.referencePathM = 0.0185;
    const player::Assessment a = player::assessSession(r, desc);
    auto v = [&](const char* n) {
        const player::MetricResult* m = a.find(n);
        EXPECT_TRUE(m && m->value) << n;
        return m && m->value ? *m->value : std::nan("");
    };
    EXPECT_NEAR(v("path_length_left_m"), 0.018, 1e-12);
    EXPECT_NEAR(v("path_length_right_m"), 0.019, 1e-12);
    EXPECT_NEAR(v("path_length_m"), 0.037, 1e-12);
    EXPECT_NEAR(v("economy_of_motion"), 0.0185 / 0.037, 1e-12);
    EXPECT_NEAR(v("idle_time_s"), 1.0, 1e-9) << "samples 20..29 still (the last repeats its span)";
    EXPECT_NEAR(v("force_max_n"), 2.0, 1e-12);
    EXPECT_NEAR(v("force_mean_n"), 1.25, 1e-12) << "mean over both tools' samples in contact";
    EXPECT_NEAR(v("force_over_threshold_s"), 3.0, 1e-9) << "the right tool over 1.5 N throughout";
    EXPECT_NEAR(v("tissue_damage_ns"), 0.5 * 3.0, 1e-9);
    EXPECT_EQ(v("instrument_collisions"), 0.0) << "0.2 m apart";
    // Jerk: zero at constant speed; at each stop one moving window of Δ³x = −step (2 mm and
    // 1 mm over h³ = 1e-3 s³) among 8 and 18 moving windows.
    EXPECT_NEAR(v("jerk_rms_m_s3"), std::sqrt((2.0 * 2.0 + 1.0 * 1.0) / 26.0), 1e-6);
    EXPECT_EQ(a.find("completion_time_s"), nullptr) << "no targets: no completion time";
    EXPECT_EQ(a.find("out_of_view_s"), nullptr) << "no laparoscope";
}

TEST(Assessment, TipsCloserThanTheirRadiiCountOneCollisionPerApproach) {
    player::SessionResult r =
        timeline(30, {mover("a", "left", 30, 0, 0, 0), mover("b", "right", 30, 30, 0.01, 0, Vec3(-0.02, 0, 0))});
    // b passes a at 10 mm/s: within 2 + 2 + 2 mm for 0.6 s, one approach.
    const player::Assessment a = player::assessSession(r, sim::AssessmentDesc{});
    EXPECT_EQ(*a.find("instrument_collisions")->value, 1.0);
}

TEST(Assessment, OutOfViewCountsInstrumentsInUseOutsideTheScopesCone) {
    player::SessionResult r = timeline(20, {mover("a", "right", 20, 20, 0.05, 0, Vec3(0, 0, 0))});
    r.timeline.cameraFovDeg = 60;
    for (size_t i = 0; i < 20; ++i) { // the scope at x = -0.05 looking along +x, then turned away
        r.timeline.cameraTip.push_back(Vec3(-0.05, 0, 0));
        r.timeline.cameraView.push_back(Vec3(i < 10 ? 1 : -1, 0, 0)); // turned away for the second second
    }
    const player::Assessment a = player::assessSession(r, sim::AssessmentDesc{});
    EXPECT_NEAR(*a.find("out_of_view_s")->value, 1.0, 1e-9);
}

// The hook cuts along 40 of a 50 mm line (every 1 mm) and 3 edges 10 mm off it; two clips at the
// target, one far away.
TEST(Assessment, TargetsAreMetInTimeAndCutsAndClipsOutsideThemCount) {
    player::SessionResult r = timeline(60, {mover("hook", "right", 60, 0, 0, 0)});
    for (int k = 0; k <= 40; ++k)
        r.timeline.events.push_back({0.05 * k, k, "cut", "hook", 1, Vec3(0.001 * k, 0, 0)});
    r.timeline.events.push_back({2.5, 50, "cut", "hook", 3, Vec3(0.02, 0.01, 0)});
    r.timeline.events.push_back({3.0, 60, "clip", "clipper", 1, Vec3(0.0101, 0, 0)});
    r.timeline.events.push_back({3.5, 70, "clip", "clipper", 1, Vec3(0.05, 0.05, 0)});
    r.timeline.events.push_back({4.0, 80, "clip", "clipper", 1, Vec3(0.0099, 0.001, 0)});
    sim::AssessmentDesc d;
    d.cuts.push_back({{Vec3(0, 0, 0), Vec3(0.05, 0, 0)}, 0.002, 0.8});
    d.clips.push_back({Vec3(0.01, 0, 0), 0.003, 2});
    d.metrics = {{"cut_coverage", 0.8, {}}, {"clips_off_target", 0.0, {}}};
    const player::Assessment a = player::assessSession(r, d);
    // Opened: 0 .. 40 mm along the cuts' pass, 1 mm beyond each end: 41 of 50 mm.
    EXPECT_NEAR(*a.find("cut_coverage")->value, 0.82, 0.011);
    EXPECT_EQ(*a.find("cut_outside_edges")->value, 3.0);
    EXPECT_EQ(*a.find("clips_on_target")->value, 2.0);
    EXPECT_EQ(*a.find("clips_off_target")->value, 1.0);
    // Coverage 0.8 reached at the cut at 39 mm (40 mm covered): 1.95 s; clips at 4.0 s.
    ASSERT_TRUE(a.completionS);
    EXPECT_NEAR(*a.completionS, 4.0, 1e-12);
    EXPECT_TRUE(a.find("cut_coverage")->passed);
    EXPECT_FALSE(a.find("clips_off_target")->passed);
    EXPECT_FALSE(a.passed) << "one metric failed: the session fails";
    EXPECT_THAT(player::assessmentSummary(a), HasSubstr("verdict       FAIL (clips_off_target)"));
}

// Clip sites are picked on the rest pose: a clip counts for the site nearest where it holds the
// anatomy at rest, not where the sagging vessel happened to hang when it fired.
TEST(Assessment, ClipsAreJudgedWhereTheyHoldTheAnatomyAtRest) {
    player::SessionResult r = timeline(60, {mover("clipper", "right", 60, 0, 0, 0)});
    const Vec3 site(0.01, 0, 0.008);
    // fired on the vessel hanging 6 mm below its rest place: at rest the held region is on the site
    r.timeline.events.push_back({1.0, 20, "clip", "clipper", 1, site - Vec3(0, 0, 0.006), {}, site});
    // fired where the site hangs now, on a stretch whose rest place is 6 mm away: off target
    r.timeline.events.push_back({2.0, 40, "clip", "clipper", 1, site, {}, site + Vec3(0, 0.006, 0)});
    // no rest place known (an older report): judged where it fired
    r.timeline.events.push_back({3.0, 60, "clip", "clipper", 1, site + Vec3(0.001, 0, 0)});
    sim::AssessmentDesc d;
    d.clips.push_back({site, 0.004, 2});
    const player::Assessment a = player::assessSession(r, d);
    EXPECT_EQ(*a.find("clips_on_target")->value, 2.0);
    EXPECT_EQ(*a.find("clips_off_target")->value, 1.0);
    ASSERT_TRUE(a.completionS);
    EXPECT_NEAR(*a.completionS, 3.0, 1e-12);
}

// Punctures on either side of the wound's plane z = 0: a bite is a pass through the wall on one
// side (two punctures) followed by one on the other; a bite too shallow is missed.
TEST(Assessment, BitesAcrossTheWoundAreCountedWithDepthAndSpacing) {
    player::SessionResult r = timeline(10, {});
    auto stitch = [&](double x, double depth) {
        for (double z : {-depth - 0.001, -depth, depth, depth + 0.001})
            r.puncturePoints.push_back(Vec3(x, 0, z));
    };
    stitch(0.000, 0.002);
    stitch(0.002, 0.002);
    stitch(0.004, 0.0005); // too shallow
    stitch(0.009, 0.002);  // 5 mm after the last good one
    r.suture = sim::SutureSummary{};
    r.suture->gauge = true;
    r.suture->finalGap = 0.0001;
    sim::AssessmentDesc d;
    d.suture = sim::SutureTarget{Vec3::Zero(), Vec3::UnitZ(), 3, 0.001, 0.006, 0.001, 0.003, 0.0002};
    const player::Assessment a = player::assessSession(r, d);
    EXPECT_EQ(*a.find("bites")->value, 3.0);
    EXPECT_EQ(*a.find("bites_missed")->value, 1.0);
    EXPECT_NEAR(*a.find("bite_spacing_error_m")->value, 0.007 - 0.003, 1e-12) << "0 → 2 → 9 mm";
    EXPECT_NEAR(*a.find("final_gap_m")->value, 0.0001, 1e-15);
}

TEST(Assessment, LimitsAndExpertLevelsAreJudgedOnTheBetterSide) {
    player::SessionResult r = timeline(11, {mover("a", "left", 11, 11, 0.01, 0)}); // path 10 mm
    sim::AssessmentDesc d;
    d.referencePathM = 0.008; // economy 0.8, higher is better
    d.metrics = {{"path_length_m", 0.009, sim::ExpertLevel{0.006, 0.001}},
                 {"economy_of_motion", 0.7, sim::ExpertLevel{0.9, 0.02}}};
    const player::Assessment a = player::assessSession(r, d);
    const player::MetricResult& p = *a.find("path_length_m");
    EXPECT_FALSE(p.passed) << "10 mm over a 9 mm limit";
    EXPECT_DOUBLE_EQ(p.bound, 0.008);
    EXPECT_FALSE(*p.withinExpert);
    const player::MetricResult& e = *a.find("economy_of_motion");
    EXPECT_TRUE(e.passed) << "0.8 at least 0.7";
    EXPECT_NEAR(e.bound, 0.86, 1e-12);
    EXPECT_FALSE(*e.withinExpert);
    EXPECT_FALSE(a.withinExpertLevel());
    EXPECT_EQ(player::metricLine(p), "path_length_m 0.01 m (limit ≤ 0.009) FAIL, expert ≤ 0.008: outside");
    EXPECT_EQ(player::metricLine(e), "economy_of_motion 0.8 ratio (limit ≥ 0.7) pass, expert ≥ 0.86: outside");
}

TEST(Assessment, NonFiniteFiguresAreLeftOutAndFailTheirLimit) {
    player::SessionResult r = timeline(5, {mover("a", "left", 5, 5, 0.01, 0)});
    r.timeline.tools[0].tip[2] = Vec3::Constant(std::nan("")); // a gap: skipped, never NaN
    r.timeline.tools[0].force_n[3] = std::nan("");
    const player::Assessment a = player::assessSession(r, sim::AssessmentDesc{});
    EXPECT_TRUE(std::isfinite(*a.find("path_length_m")->value));
    EXPECT_TRUE(std::isfinite(*a.find("force_mean_n")->value));
    player::SessionResult none = timeline(5, {mover("a", "left", 5, 5, 0.01, 0)});
    sim::AssessmentDesc d;
    d.clips.push_back({Vec3::Zero(), 0.01, 1});
    d.metrics = {{"completion_time_s", 10.0, {}}};
    const player::Assessment b = player::assessSession(none, d);
    EXPECT_FALSE(b.find("completion_time_s")->value) << "no clip: the targets were never met";
    EXPECT_FALSE(b.find("completion_time_s")->passed);
    EXPECT_EQ(player::formatFigure(std::nullopt), "—");
    EXPECT_EQ(player::formatFigure(std::nan("")), "—");
    EXPECT_EQ(player::formatFigure(-0.0), "0");
    EXPECT_EQ(player::formatFigure(0.00612), "0.00612");
    EXPECT_EQ(player::formatFigure(12.345), "12.3");
    EXPECT_EQ(player::formatFigure(2130.0), "2130");
}

// Every metric has its unit and definition in the trainee's guide (packaging/doc), under its name.
TEST(Assessment, EveryMetricIsDocumentedInTheTraineesGuide) {
    std::ifstream in(std::string(VISCERA_SOURCE_DIR) + "/packaging/doc/trainee-guide.md");
    const std::string guide((std::istreambuf_iterator<char>(in)), {});
    ASSERT_FALSE(guide.empty());
    for (const sim::MetricInfo& m : sim::metricCatalogue()) {
        EXPECT_NE(guide.find("`" + std::string(m.name) + "`"), std::string::npos) << m.name;
        EXPECT_FALSE(m.definition.empty()) << m.name;
    }
}

// A tool that declares its own damage threshold (damage_force_n) is judged by it; the others by
// the case's force_threshold_n.
TEST(Assessment, AToolsOwnDamageThresholdTakesPrecedenceOverTheCases) {
    player::SessionResult r =
        timeline(30, {mover("own", "left", 30, 0, 0, 2.0), mover("case", "right", 30, 0, 0, 2.0)});
    r.timeline.tools[0].damageForceN = 3.0;
    sim::AssessmentDesc d;
    d.forceThresholdN = 1.5;
    const player::Assessment a = player::assessSession(r, d);
    EXPECT_EQ(a.tools[0].overThresholdS, 0.0) << "2 N under its own 3 N";
    EXPECT_NEAR(a.tools[1].overThresholdS, 3.0, 1e-9);
    EXPECT_NEAR(*a.find("tissue_damage_ns")->value, 0.5 * 3.0, 1e-9);
    EXPECT_NEAR(*a.find("force_over_threshold_s")->value, 3.0, 1e-9);
}

// A stitch through one wall only is a missed bite, and its neighbours still make theirs; badly
// spaced bites keep the suture target from being met even when the gap closes.
TEST(Assessment, AStitchThroughOneWallIsMissedAndBadSpacingKeepsTheTargetOpen) {
    player::SessionResult r = timeline(10, {});
    auto wall = [&](double x, double z0, double z1) {
        r.puncturePoints.push_back(Vec3(x, 0, z0));
        r.puncturePoints.push_back(Vec3(x, 0, z1));
    };
    wall(0.000, -0.003, -0.002), wall(0.000, 0.002, 0.003); // bite
    wall(0.002, -0.003, -0.002);                            // through one wall only
    wall(0.004, -0.003, -0.002), wall(0.004, 0.002, 0.003); // bite
    r.suture = sim::SutureSummary{};
    r.suture->gauge = true;
    r.suture->finalGap = 0.0001;
    sim::AssessmentDesc d;
    d.suture = sim::SutureTarget{Vec3::Zero(), Vec3::UnitZ(), 2, 0.001, 0.006, 0.001, 0.003, 0.0002};
    player::Assessment a = player::assessSession(r, d);
    EXPECT_EQ(*a.find("bites")->value, 2.0);
    EXPECT_EQ(*a.find("bites_missed")->value, 1.0);
    EXPECT_NEAR(*a.find("bite_spacing_error_m")->value, 0.001, 1e-12) << "4 mm between the two bites, 3 mm allowed";
    EXPECT_FALSE(a.completionS) << "two bites and the gap closed, but spaced too far apart";
    d.suture->spacingMax = 0.005;
    a = player::assessSession(r, d);
    EXPECT_TRUE(a.completionS);
}

// A metric the case judges but this session could not measure fails its limit, listed without
// a value; a target metric without its target is refused when the case is read.
TEST(Assessment, AJudgedMetricTheSessionCannotMeasureFailsAndOneWithoutItsTargetIsRefused) {
    player::SessionResult r = timeline(5, {mover("a", "left", 5, 5, 0.01, 0)});
    sim::AssessmentDesc d;
    d.metrics = {{"out_of_view_s", 2.0, {}}}; // no laparoscope in this session
    const player::Assessment a = player::assessSession(r, d);
    ASSERT_TRUE(a.find("out_of_view_s"));
    EXPECT_FALSE(a.find("out_of_view_s")->value);
    EXPECT_FALSE(a.passed);
    EXPECT_THAT(refusal(R"({"metrics": {"cut_coverage": {"limit": 0.8}}})"),
                HasSubstr("assessment.metrics.cut_coverage: needs a cut target (targets.cut)"));
    EXPECT_THAT(refusal(R"({"metrics": {"completion_time_s": {"limit": 8}}})"),
                HasSubstr("assessment.metrics.completion_time_s: needs a target"));
    EXPECT_THAT(refusal(R"({"metrics": {"economy_of_motion": {"limit": 0.5}}})"),
                HasSubstr("assessment.metrics.economy_of_motion: needs reference_path_m"));
}

// Cuts every 3 mm along a line with a 5 mm radius open it along the way (one pass), but cuts
// 10 mm apart open only 1 mm either side of each, however wide the radius.
TEST(Assessment, CutCoverageIsTheLengthOpenedNotTheRadiusAroundEachCut) {
    auto coverage = [](double step) {
        player::SessionResult r = timeline(10, {mover("hook", "right", 10, 0, 0, 0)});
        for (int k = 0; k * step <= 0.02 + 1e-12; ++k)
            r.timeline.events.push_back({0.1 * k, k, "cut", "hook", 1, Vec3(k * step, 0, 0)});
        sim::AssessmentDesc d;
        d.cuts.push_back({{Vec3(0, 0, 0), Vec3(0.02, 0, 0)}, 0.005, 0.5});
        return *player::assessSession(r, d).find("cut_coverage")->value;
    };
    EXPECT_NEAR(coverage(0.003), 19.0 / 20, 1e-9) << "one pass, 3 mm steps from 0 to 18 mm, 1 mm beyond";
    EXPECT_NEAR(coverage(0.01), 4.0 / 20, 1e-9) << "cuts at 0, 10 and 20 mm: 1 + 2 + 1 mm opened";
}

// With cut targets only, the completion time is the cut at which the coverage was reached: cuts
// every 1 mm along a 50 mm line, 80 % (40 mm, with 1 mm beyond the last cut) at the cut at 39 mm.
TEST(Assessment, TheCompletionTimeIsWhenTheLastTargetWasMet) {
    player::SessionResult r = timeline(60, {mover("hook", "right", 60, 0, 0, 0)});
    for (int k = 0; k <= 45; ++k)
        r.timeline.events.push_back({0.05 * k, k, "cut", "hook", 1, Vec3(0.001 * k, 0, 0)});
    r.timeline.events.push_back(
        {2.4, 48, "cut", "hook", 2, Vec3::Constant(std::nan(""))}); // no hook position: counted outside
    sim::AssessmentDesc d;
    d.cuts.push_back({{Vec3(0, 0, 0), Vec3(0.05, 0, 0)}, 0.002, 0.8});
    const player::Assessment a = player::assessSession(r, d);
    ASSERT_TRUE(a.completionS);
    EXPECT_NEAR(*a.completionS, 0.05 * 39, 1e-12);
    EXPECT_EQ(*a.find("cut_outside_edges")->value, 2.0);
}

// Every judged metric is one the scene can measure; a scene that could never give one is refused.
TEST(Assessment, AMetricTheSceneCannotMeasureIsRefusedWhenTheSceneIsRead) {
    EXPECT_THAT(refusal(R"({"metrics": {"out_of_view_s": {"limit": 2}}})"),
                HasSubstr("assessment.metrics.out_of_view_s: needs a laparoscope"));
    EXPECT_THAT(refusal(R"({"metrics": {"final_gap_m": {"limit": 0.001}}})"),
                HasSubstr("assessment.metrics.final_gap_m: needs a suture with a gauge"));
    EXPECT_THAT(refusal(R"({"metrics": {"path_length_m": {"limit": 1}}})"),
                HasSubstr("assessment.metrics.path_length_m: needs a tool"));
}

// Vessel injury: the samples in which an energized hook was within the margin of the vessel to
// protect, in seconds; a vessel that is not a body of the scene is refused.
TEST(Assessment, VesselInjuryIsTheTimeTheEnergizedHookSpentAtTheVessel) {
    player::SessionResult r = timeline(20, {mover("hook", "right", 20, 0, 0, 0)});
    r.timeline.vesselNear.assign(20, 0);
    for (size_t i = 5; i < 9; ++i)
        r.timeline.vesselNear[i] = 1;
    sim::AssessmentDesc d;
    d.vessel = sim::VesselTarget{"vessel", 0.0015};
    d.metrics = {{"vessel_injury_s", 0.1, {}}};
    const player::Assessment a = player::assessSession(r, d);
    EXPECT_NEAR(*a.find("vessel_injury_s")->value, 0.4, 1e-9);
    EXPECT_FALSE(a.find("vessel_injury_s")->passed);
    EXPECT_EQ(a.completionS, std::nullopt) << "a vessel to protect is not a task target";
    EXPECT_THAT(refusal(R"({"targets": {"vessel": {"body": "aorta"}}})"),
                HasSubstr("assessment.targets.vessel.body: 'aorta' is not a body of the scene"));
    EXPECT_THAT(refusal(R"({"metrics": {"vessel_injury_s": {"limit": 0.1}}})"),
                HasSubstr("assessment.metrics.vessel_injury_s: needs a vessel to protect (targets.vessel)"));
}
