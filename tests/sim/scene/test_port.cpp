// Trocar ports (sim/scene/port.hpp): the shaft through the port, insertion and angle limits, the
// fulcrum's sign and lever, the hand force against finite differences of the fulcrum map
// (virtual work), non-finite input, the "port" block's rules, and instruments of a world on
// their tracks through ports.
#include "interaction_rig.hpp"
#include "sim/scene/interaction.hpp"
#include "sim/scene/interaction_runtime.hpp"
#include "sim/scene/port.hpp"
#include "sim/util/error.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

using namespace viscera::sim;
using ::testing::HasSubstr;

namespace {

/// A port 10 cm above the origin, the rest tip 8 cm below it (straight down).
PortFrame downPort(PortMode mode = PortMode::Laparoscopic) {
    PortDesc p;
    p.declared = true;
    p.position = Vec3(0, 0, 0.10);
    p.insertionMin = 0.03;
    p.insertionMax = 0.15;
    p.maxAngleDeg = 40;
    p.shaftLength = 0.30;
    p.mode = mode;
    return makePortFrame(p, Vec3(0, 0, 0.02), 0.4);
}

} // namespace

TEST(Port, TheShaftPassesThroughThePortAndTheTipStaysWithinItsLimits) {
    const PortFrame port = downPort();
    const Vec3 targets[] = {Vec3(0.01, 0.02, 0.0), Vec3(0, 0, 0.09), Vec3(0, 0, -0.2),
                            Vec3(0.3, 0, 0.05),    Vec3(0, 0, 0.5),  Vec3(-0.02, 0.03, 0.04)};
    for (const Vec3& t : targets) {
        const PortPose pose = constrainToPort(port, t);
        EXPECT_LT(shaftDistanceToPort(port.desc.position, pose.tip, pose.direction, 0.3), 1e-12);
        EXPECT_GE(pose.insertion, port.desc.insertionMin - 1e-12);
        EXPECT_LE(pose.insertion, port.desc.insertionMax + 1e-12);
        EXPECT_NEAR((pose.tip - port.desc.position).norm(), pose.insertion, 1e-12);
        const double angle = std::acos(std::clamp(pose.direction.dot(port.axis), -1.0, 1.0)) * 180 / M_PI;
        EXPECT_LE(angle, port.desc.maxAngleDeg + 1e-9);
    }
    // Within the limits the tip is where it was asked to be.
    const PortPose inside = constrainToPort(port, Vec3(0.01, 0.02, 0.0));
    EXPECT_LT((inside.tip - Vec3(0.01, 0.02, 0.0)).norm(), 1e-12);
    EXPECT_FALSE(inside.insertionLimited || inside.angleLimited);
    // Too shallow, too deep, too far sideways.
    EXPECT_TRUE(constrainToPort(port, Vec3(0, 0, 0.09)).insertionLimited);
    EXPECT_NEAR(constrainToPort(port, Vec3(0, 0, 0.09)).insertion, 0.03, 1e-12);
    EXPECT_TRUE(constrainToPort(port, Vec3(0, 0, -0.2)).insertionLimited);
    EXPECT_NEAR(constrainToPort(port, Vec3(0, 0, -0.2)).insertion, 0.15, 1e-12);
    EXPECT_TRUE(constrainToPort(port, Vec3(0.3, 0, 0.05)).angleLimited);
    // A target on the port or behind it (outside the body) comes back inside.
    EXPECT_GT(port.axis.dot(constrainToPort(port, Vec3(0, 0, 0.5)).direction), std::cos(40 * M_PI / 180) - 1e-9);
    EXPECT_TRUE(constrainToPort(port, port.desc.position).tip.allFinite());
}

TEST(Port, TheFulcrumMovesTheTipOppositeToTheHandByTheLeverRatio) {
    const PortFrame port = downPort();
    const PortPose rest = fulcrumTip(port, port.restHandle);
    EXPECT_LT((rest.tip - port.restTip).norm(), 1e-12) << "the rest handle holds the rest tip";
    // Hand 1 mm to +x: the tip goes to −x by insertion / outside of it.
    const double h = 1e-3;
    const PortPose moved = fulcrumTip(port, port.restHandle + Vec3(h, 0, 0));
    const double lever = 0.08 / (0.30 - 0.08);
    EXPECT_LT(moved.tip.x(), 0.0) << "the fulcrum effect: the tip moves opposite to the hand";
    EXPECT_NEAR(moved.tip.x() / h, -lever, 1e-3);
    // handScale makes the tip's sideways motion per device metre the mapping's motion scale.
    EXPECT_NEAR(port.handScale * lever, 0.4, 1e-12);
    // Pushing the handle towards the port inserts the tip by as much.
    const PortPose deeper = fulcrumTip(port, port.restHandle - Vec3(0, 0, h)); // down, towards the port
    EXPECT_NEAR(deeper.insertion - rest.insertion, h, 1e-9);
    EXPECT_LT(shaftDistanceToPort(port.desc.position, moved.tip, moved.direction, 0.3), 1e-12);
    // fulcrumHandle inverts fulcrumTip.
    for (const Vec3& t : {Vec3(0.01, -0.02, 0.01), Vec3(-0.03, 0.0, 0.04)}) {
        const PortPose p = fulcrumTip(port, fulcrumHandle(port, t));
        EXPECT_LT((p.tip - t).norm(), 1e-12);
    }
    // The handle pushed on across the port's level (1 mm steps, 2 cm to the side): the tip stays
    // fully in and never jumps.
    Vec3 last = fulcrumTip(port, port.desc.position + Vec3(0.02, 0, 0.05)).tip;
    double worstStep = 0;
    for (int k = 1; k <= 100; ++k) {
        const PortPose p = fulcrumTip(port, port.desc.position + Vec3(0.02, 0, 0.05 - 0.001 * k));
        ASSERT_TRUE(p.tip.allFinite());
        worstStep = std::max(worstStep, (p.tip - last).norm());
        last = p.tip;
    }
    EXPECT_LT(worstStep, 0.01) << "no jump as the handle crosses the port's level";
    EXPECT_NEAR((last - port.desc.position).norm(), port.desc.insertionMax, 1e-9);
    // The handle pulled out past the shaft's length: the tip stops at the shortest insertion.
    const PortPose out = fulcrumTip(port, port.desc.position + Vec3(0, 0, 0.40));
    EXPECT_TRUE(out.insertionLimited);
    EXPECT_NEAR(out.insertion, port.desc.insertionMin, 1e-12);
}

TEST(Port, TheHandForceIsTheTipForceThroughTheLeverByVirtualWork) {
    // Power balance: F_hand · δH = F_tip · δT for small handle moves δH (finite differences of
    // fulcrumTip), at several poses and forces.
    const PortFrame port = downPort();
    const Vec3 tips[] = {Vec3(0, 0, 0.02), Vec3(0.02, -0.01, 0.0), Vec3(-0.03, 0.02, 0.03)};
    const Vec3 forces[] = {Vec3(0.3, 0, 0), Vec3(0, 0, 1.2), Vec3(-0.4, 0.7, 0.5)};
    double worst = 0;
    for (const Vec3& tip : tips)
        for (const Vec3& f : forces) {
            const Vec3 handle = fulcrumHandle(port, tip);
            const PortPose pose = fulcrumTip(port, handle);
            const Vec3 fh = handForce(port, pose, f);
            for (int k = 0; k < 3; ++k) {
                const double h = 1e-6;
                const Vec3 e = Vec3::Unit(k) * h;
                const Vec3 dT = (fulcrumTip(port, handle + e).tip - fulcrumTip(port, handle - e).tip) / (2 * h);
                const double err = std::abs(fh[k] - f.dot(dT));
                worst = std::max(worst, err / std::max(1.0, f.norm()));
                EXPECT_NEAR(fh[k], f.dot(dT), 1e-6 * std::max(1.0, f.norm())) << "component " << k;
            }
        }
    std::printf("hand force against virtual work: worst relative error %.2e\n", worst);
    // Sideways on the tip pushes the hand the other way, scaled by the lever.
    const PortPose rest = fulcrumTip(port, port.restHandle);
    const Vec3 fh = handForce(port, rest, Vec3(1, 0, 0));
    EXPECT_NEAR(fh.x(), -0.08 / 0.22, 1e-9);
    // Robotic mode: the tip force itself.
    const PortFrame robot = downPort(PortMode::Robotic);
    EXPECT_EQ(handForce(robot, rest, Vec3(1, 2, 3)), Vec3(1, 2, 3));
}

TEST(Port, NonFiniteInputGivesTheRestPoseNeverNaN) {
    const PortFrame port = downPort();
    const double nan = std::nan("");
    const PortPose a = constrainToPort(port, Vec3(nan, 0, 0));
    EXPECT_TRUE(a.tip.allFinite() && a.direction.allFinite());
    EXPECT_LT((a.tip - port.restTip).norm(), 1e-12);
    EXPECT_TRUE(fulcrumTip(port, Vec3(0, INFINITY, 0)).tip.allFinite());
    EXPECT_TRUE(fulcrumHandle(port, Vec3(nan, nan, nan)).allFinite());
    EXPECT_EQ(handForce(port, a, Vec3(nan, 0, 0)), Vec3::Zero());
    EXPECT_EQ(twistAbout(Eigen::Vector4d(nan, 0, 0, 0), Vec3::UnitZ()), 0.0);
    // The twist about the axis of a rotation about that axis is its angle.
    const Eigen::Quaterniond q(Eigen::AngleAxisd(0.7, Vec3::UnitZ()) * Eigen::AngleAxisd(0.2, Vec3::UnitX()));
    EXPECT_NEAR(twistAbout(Eigen::Vector4d(1, 0, 0, 0), Vec3::UnitZ()), 0.0, 1e-15);
    const Eigen::Quaterniond roll(Eigen::AngleAxisd(0.7, Vec3::UnitZ()));
    EXPECT_NEAR(twistAbout(Eigen::Vector4d(roll.w(), roll.x(), roll.y(), roll.z()), Vec3::UnitZ()), 0.7, 1e-12);
    EXPECT_TRUE(std::isfinite(twistAbout(Eigen::Vector4d(q.w(), q.x(), q.y(), q.z()), Vec3::UnitZ())));
}

TEST(Port, TheBlockRoundTripsAndBadBlocksNameTheFieldAndRule) {
    const char* ok = R"({"instruments": [{"name": "g", "kind": "grasper", "track": "t.track",
        "port": {"position": [0.07, -0.08, 0.1], "insertion": [0.02, 0.25], "max_angle_deg": 50,
                 "shaft_length": 0.36, "mode": "robotic"}}]})";
    const InteractionDesc d = parseInteractionSection(ok, "scene.json");
    ASSERT_TRUE(d.instruments[0].port.declared);
    EXPECT_EQ(d.instruments[0].port.mode, PortMode::Robotic);
    EXPECT_DOUBLE_EQ(d.instruments[0].port.insertionMax, 0.25);
    const InteractionDesc back = parseInteractionSection(formatInteractionSection(d), "back");
    EXPECT_EQ(back.instruments[0].port.position, d.instruments[0].port.position);
    EXPECT_DOUBLE_EQ(back.instruments[0].port.maxAngleDeg, 50);
    EXPECT_EQ(back.instruments[0].port.mode, PortMode::Robotic);
    auto error = [](const std::string& port) {
        const std::string json =
            R"({"instruments": [{"name": "g", "kind": "grasper", "track": "t.track", "port": )" + port + "}]}";
        try {
            parseInteractionSection(json, "scene.json");
        } catch (const viscera::InputError& e) {
            return std::string(e.what());
        }
        return std::string("accepted");
    };
    EXPECT_THAT(error(R"({"insertion": [0.02, 0.2]})"), HasSubstr("instruments[0].port.position: required field"));
    EXPECT_THAT(error(R"({"position": [0, 0, 0.1], "insertion": [0.2, 0.1]})"),
                HasSubstr("instruments[0].port.insertion: must be [min, max] with min < max"));
    EXPECT_THAT(error(R"({"position": [0, 0, 0.1], "insertion": [0.02, 0.3], "shaft_length": 0.3})"),
                HasSubstr("instruments[0].port.shaft_length: must be at least the largest insertion + 0.05 m"));
    EXPECT_THAT(error(R"({"position": [0, 0, 0.1], "mode": "magnetic"})"),
                HasSubstr("instruments[0].port.mode: 'magnetic' is not a port mode (laparoscopic, robotic)"));
    EXPECT_THAT(error(R"({"position": [0, 0, 0.1], "max_angle_deg": 95})"),
                HasSubstr("instruments[0].port.max_angle_deg: must be in (0, 89]"));
    EXPECT_THAT(error(R"({"position": [0, "x", 0.1]})"), HasSubstr("instruments[0].port.position[1]"));
}

TEST(Port, InstrumentsOnTheirTracksPassThroughTheirPortsInEveryFrame) {
    // The interaction rig with the grasper, hook and clipper each through a port 9 cm above the
    // pad; their tracks point straight down, so the port changes their directions.
    test::Rig rig = test::makeRig();
    const Vec3 ports[] = {Vec3(-0.03, -0.03, 0.09), Vec3(0.07, -0.02, 0.08), Vec3(0.07, -0.02, 0.08)};
    for (size_t i = 0; i < 3; ++i) {
        PortDesc& p = rig.scene.interaction->instruments[i].port;
        p.declared = true;
        p.position = ports[i];
        p.insertionMin = 0.02;
        p.insertionMax = 0.2;
        p.maxAngleDeg = 60;
        p.mode = PortMode::Robotic;
    }
    std::unique_ptr<World> w = test::assemble(std::move(rig));
    double worst = 0;
    for (int f = 0; f < 36; ++f) {
        ASSERT_TRUE(w->step().finite) << "frame " << f;
        for (size_t i = 0; i < 3; ++i) {
            const InstrumentState& s = w->interaction()->summary().instruments.at(i);
            // The collision shape's shaft as posed (its frame's origin and axis), not the state
            // the port built: the geometry the tissue meets passes through the port.
            const double d = shaftDistanceToPort(ports[i], s.shaftPoint, s.shaftAxis, 0.36);
            worst = std::max(worst, d);
            EXPECT_LT(d, 5e-4) << s.name << " frame " << f;
            EXPECT_GT(s.direction.z(), -1 + 1e-3) << "no longer vertical";
        }
    }
    const InteractionSummary& s = w->interaction()->summary();
    std::printf("through ports: worst shaft-to-port distance %.3g mm; fascia edges cut %d, grasps %d, clips %zu\n",
                worst * 1e3, s.fasciaEdgesCut, s.grasps, s.clips.size());
    EXPECT_GT(s.fasciaEdgesCut, 10) << "the hook still cuts through its port";
    EXPECT_EQ(s.grasps, 1);
    EXPECT_EQ(s.clips.size(), 1u);
}

TEST(Port, AWorldRefusesATrackWhoseFirstTipLiesOutsideThePortsInsertion) {
    test::Rig rig = test::makeRig();
    PortDesc& p = rig.scene.interaction->instruments[1].port;
    p.declared = true;
    p.position = Vec3(0.0, 0.0, 0.5); // 0.49 m from the hook's first tip
    p.insertionMax = 0.3;
    try {
        test::assemble(std::move(rig));
        FAIL() << "accepted a port the track cannot reach";
    } catch (const viscera::InputError& e) {
        EXPECT_THAT(e.what(), HasSubstr("interaction.instruments[1].port: the track's first tip lies 0.4"));
        EXPECT_THAT(e.what(), HasSubstr("m from its port, outside the port's insertion [0.02, 0.3]"));
    }
}
