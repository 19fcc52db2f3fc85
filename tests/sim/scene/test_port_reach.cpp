// Port reach (sim/scene/port_reach.hpp): which task targets an instrument cannot reach through its
// port — inside the cone and the insertion range nothing is flagged, past the angle or the range
// the problem names the instrument, the target, the point and the rule; graspers and tools with no
// port or no track are not checked; non-finite targets are reported, never NaN.
#include "sim/scene/instrument_track.hpp"
#include "sim/scene/port_reach.hpp"
#include "sim/scene/scene.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

using namespace viscera::sim;
using ::testing::HasSubstr;

namespace {

/// A port 10 cm above the origin; the tool rests 8 cm below it (straight down), 40° cone,
/// insertion [0.03, 0.15].
InstrumentDesc tool(InstrumentDesc::Kind kind, const std::string& name) {
    InstrumentDesc in;
    in.name = name;
    in.kind = kind;
    in.port.declared = true;
    in.port.position = Vec3(0, 0, 0.10);
    in.port.insertionMin = 0.03;
    in.port.insertionMax = 0.15;
    in.port.maxAngleDeg = 40;
    in.port.shaftLength = 0.30;
    InstrumentKey k;
    k.position = Vec3(0, 0, 0.02);
    in.trackText = InstrumentTrack({k}).format();
    return in;
}

SceneDesc sceneWith(std::vector<InstrumentDesc> tools, std::vector<Vec3> cutLine, std::vector<Vec3> clips) {
    SceneDesc s;
    s.interaction = InteractionDesc{};
    s.interaction->instruments = std::move(tools);
    AssessmentDesc a;
    if (!cutLine.empty()) a.cuts.push_back({std::move(cutLine), 0.004, 0.8});
    for (const Vec3& c : clips)
        a.clips.push_back({c, 0.006, 1});
    s.assessment = a;
    return s;
}

} // namespace

TEST(PortReach, TargetsInsideTheConeAndTheRangeAreReached) {
    const SceneDesc s =
        sceneWith({tool(InstrumentDesc::Kind::EnergyHook, "hook"), tool(InstrumentDesc::Kind::ClipApplier, "clipper")},
                  {Vec3(-0.03, 0, 0), Vec3(0.03, 0, 0)}, {Vec3(0.01, 0.01, 0.0)});
    EXPECT_TRUE(unreachableTargets(s).empty());
}

TEST(PortReach, ACutLineBeyondTheAngleNamesTheToolTheTargetAndTheRule) {
    // 0.09 m off axis at 0.1 m depth: atan(0.09/0.1) = 42° > 40°; the line's first vertex is fine.
    const SceneDesc s =
        sceneWith({tool(InstrumentDesc::Kind::EnergyHook, "hook")}, {Vec3(0, 0, 0), Vec3(0.09, 0, 0)}, {});
    const auto problems = unreachableTargets(s);
    ASSERT_EQ(problems.size(), 1u);
    EXPECT_EQ(problems[0].instrument, 0u);
    EXPECT_EQ(problems[0].target, "assessment.targets.cut[0]");
    // the first sampled point past 40° (tan(40°) · 0.1 = 0.0839) by more than the 0.1 mm
    // tolerance: 0.084 is 40.03°, its nearest allowed tip 0.07 mm away, so 0.086 (40.7°) is named
    EXPECT_GT(problems[0].point.x(), 0.0839);
    EXPECT_LT(problems[0].point.x(), 0.0839 + 2 * kReachSampleM + 1e-12);
    EXPECT_GT(problems[0].distance, 0.0);
    EXPECT_THAT(problems[0].message, HasSubstr("interaction.instruments[0] 'hook': its port cannot reach "
                                               "assessment.targets.cut[0] at (0.08"));
    EXPECT_THAT(problems[0].message, HasSubstr("beyond max_angle_deg 40.0"));
}

TEST(PortReach, AClipSiteBeyondTheInsertionRangeIsFlaggedAndAGrasperIsNotChecked) {
    const SceneDesc s =
        sceneWith({tool(InstrumentDesc::Kind::Grasper, "grasper"), tool(InstrumentDesc::Kind::ClipApplier, "clipper")},
                  {Vec3(0.2, 0, 0)}, {Vec3(0, 0, -0.1)});
    const auto problems = unreachableTargets(s);
    ASSERT_EQ(problems.size(), 1u);
    EXPECT_EQ(problems[0].instrument, 1u);
    EXPECT_EQ(problems[0].target, "assessment.targets.clip[0]");
    EXPECT_NEAR(problems[0].distance, 0.05, 1e-9); // 0.2 m from the port, held at 0.15
    EXPECT_THAT(problems[0].message, HasSubstr("0.200 m from the port, outside the insertion range [0.030, 0.150]"));
}

TEST(PortReach, ToolsWithoutAPortOrATrackAndScenesWithoutTargetsAreNotChecked) {
    InstrumentDesc noPort = tool(InstrumentDesc::Kind::EnergyHook, "a");
    noPort.port.declared = false;
    InstrumentDesc noTrack = tool(InstrumentDesc::Kind::EnergyHook, "b");
    noTrack.trackText.clear();
    InstrumentDesc badTrack = tool(InstrumentDesc::Kind::EnergyHook, "c");
    badTrack.trackText = "not a track";
    SceneDesc s = sceneWith({noPort, noTrack, badTrack}, {Vec3(1, 1, 1)}, {});
    EXPECT_TRUE(unreachableTargets(s).empty());
    s.assessment.reset();
    s.interaction->instruments = {tool(InstrumentDesc::Kind::EnergyHook, "hook")};
    EXPECT_TRUE(unreachableTargets(s).empty());
}

TEST(PortReach, ANonFiniteTargetIsReportedNeverNaN) {
    const SceneDesc s =
        sceneWith({tool(InstrumentDesc::Kind::ClipApplier, "clipper")}, {}, {Vec3(NAN, 0, 0), Vec3(0, 0, 0.0)});
    const auto problems = unreachableTargets(s);
    ASSERT_EQ(problems.size(), 1u);
    EXPECT_THAT(problems[0].message, HasSubstr("is not a finite point"));
    const PortFrame f = makePortFrame(tool(InstrumentDesc::Kind::Grasper, "g").port, Vec3(0, 0, 0.02), 1.0);
    EXPECT_EQ(reachRule(f, Vec3(0, 0, 0.0)), "");
    EXPECT_NE(reachRule(f, Vec3(INFINITY, 0, 0)), "");
}
