// The laparoscope (sim/scene/laparoscope.hpp): the optic's view against its shaft (0° and 30°),
// the image's up, steering through the port within its limits, non-finite input, the section's
// rules and the world's check of its tip against the port.
#include "interaction_rig.hpp"
#include "sim/scene/laparoscope.hpp"
#include "sim/scene/scene.hpp"
#include "sim/util/error.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

using namespace viscera::sim;
using ::testing::HasSubstr;

namespace {

LaparoscopeDesc scope(double opticDeg) {
    LaparoscopeDesc d;
    d.port.declared = true;
    d.port.position = Vec3(0, -0.15, 0.09);
    d.port.insertionMin = 0.04;
    d.port.insertionMax = 0.2;
    d.port.maxAngleDeg = 35;
    d.port.mode = PortMode::Robotic;
    d.tip = Vec3(-0.01, -0.045, 0.055);
    d.opticDeg = opticDeg;
    return d;
}

double degBetween(const Vec3& a, const Vec3& b) {
    return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)) * 180 / M_PI;
}

} // namespace

TEST(Laparoscope, TheOpticLooksAlongItsShaftOrThirtyDegreesDown) {
    for (double optic : {0.0, 30.0}) {
        const Laparoscope lap(scope(optic));
        const ScopePose& p = lap.pose();
        EXPECT_LT((p.tip - Vec3(-0.01, -0.045, 0.055)).norm(), 1e-12) << "at rest on its tip";
        EXPECT_NEAR(degBetween(p.view, p.shaft), optic, 1e-9);
        EXPECT_NEAR(p.view.norm(), 1, 1e-12);
        EXPECT_NEAR(p.up.dot(p.view), 0, 1e-12) << "the image's up is across the view";
        EXPECT_GT(p.up.z(), 0) << "and points up in the scene at roll 0";
        if (optic > 0) {
            EXPECT_LT(p.view.z(), p.shaft.z()) << "a 30° optic looks further down than its shaft";
        }
    }
}

TEST(Laparoscope, SteeringMovesTheTipThroughItsPortWithinItsLimits) {
    Laparoscope lap(scope(30));
    const LaparoscopeDesc& d = lap.desc();
    lap.grab();
    lap.steer(Vec3(0.05, 0, 0), 0); // 5 cm of the master → 1.5 cm of the tip
    EXPECT_NEAR((lap.pose().tip - d.tip).norm(), 0.3 * 0.05, 1e-12);
    EXPECT_NEAR(lap.path(), 0.015, 1e-12);
    // A new grab starts from where it is: the same move again goes as far again.
    lap.grab();
    lap.steer(Vec3(0.05, 0, 0), 0);
    EXPECT_NEAR(lap.pose().tip.x() - d.tip.x(), 0.03, 1e-3);
    // Far beyond its reach: held at the port's limits, the shaft through the port.
    for (const Vec3& m : {Vec3(0, 0, -3), Vec3(0, 3, 0), Vec3(2, 0, 1), Vec3(0, -3, 0)}) {
        lap.grab();
        lap.steer(m, 0.4);
        const ScopePose& p = lap.pose();
        ASSERT_TRUE(p.tip.allFinite() && p.view.allFinite() && p.up.allFinite());
        EXPECT_GE(p.insertion, d.port.insertionMin - 1e-12);
        EXPECT_LE(p.insertion, d.port.insertionMax + 1e-12);
        EXPECT_LT(shaftDistanceToPort(d.port.position, p.tip, p.shaft, 0.36), 1e-12);
        EXPECT_TRUE(p.atLimit);
        lap.steer(Vec3::Zero(), 0); // back where this grab began
    }
    // The twist rolls the optic about its shaft.
    Laparoscope rolled(scope(30));
    rolled.grab();
    rolled.steer(Vec3::Zero(), 0.5);
    EXPECT_NEAR(degBetween(rolled.pose().view, rolled.pose().shaft), 30, 1e-9);
    EXPECT_GT(degBetween(rolled.pose().view, Laparoscope(scope(30)).pose().view), 5);
    // Non-finite input changes nothing.
    const ScopePose before = rolled.pose();
    rolled.steer(Vec3(NAN, 0, 0), 0);
    rolled.steer(Vec3::Zero(), INFINITY);
    EXPECT_EQ(rolled.pose().tip, before.tip);
    EXPECT_EQ(rolled.pose().view, before.view);
}

TEST(Laparoscope, TheSectionRoundTripsAndBadSectionsNameTheField) {
    test::Rig rig = test::makeRig();
    rig.scene.laparoscope = scope(30);
    rig.scene.bodies[0].meshPath = "meshes/fat.vtet";
    const std::string text = formatScene(rig.scene);
    const SceneDesc back = parseScene(text, "scene.json");
    ASSERT_TRUE(back.laparoscope.has_value());
    EXPECT_EQ(back.laparoscope->tip, Vec3(-0.01, -0.045, 0.055));
    EXPECT_DOUBLE_EQ(back.laparoscope->opticDeg, 30);
    EXPECT_EQ(back.laparoscope->port.position, Vec3(0, -0.15, 0.09));
    auto error = [&](const std::string& from, const std::string& to) {
        std::string t = text;
        const size_t at = t.find(from);
        EXPECT_NE(at, std::string::npos) << from;
        t.replace(at, from.size(), to);
        try {
            parseScene(t, "scene.json");
        } catch (const viscera::InputError& e) {
            return std::string(e.what());
        }
        return std::string("accepted");
    };
    EXPECT_THAT(error("\"optic_deg\": 30.0", "\"optic_deg\": 15"),
                HasSubstr("scene.json: laparoscope.optic_deg: must be 0 or 30"));
    EXPECT_THAT(error("\"fov_deg\": 70.0", "\"fov_deg\": 170"), HasSubstr("laparoscope.fov_deg: must be in [20, 120]"));
    EXPECT_THAT(error("\"hand\": \"right\",\n    \"motion_scale\"", "\"hand\": \"foot\",\n    \"motion_scale\""),
                HasSubstr("laparoscope.hand: 'foot' is not a hand"));
    EXPECT_THAT(error("\"optic_deg\"", "\"zoom\": 2, \"optic_deg\""), HasSubstr("laparoscope.zoom: unknown field"));
}

TEST(Laparoscope, AWorldRefusesATipItsPortCannotReach) {
    test::Rig rig = test::makeRig();
    rig.scene.laparoscope = scope(30);
    rig.scene.laparoscope->tip = Vec3(0.3, 0.3, 0.3);
    try {
        test::assemble(std::move(rig));
        FAIL() << "accepted a laparoscope tip out of its port's reach";
    } catch (const viscera::InputError& e) {
        EXPECT_THAT(e.what(), HasSubstr("test: laparoscope.tip: lies 0.5"));
        EXPECT_THAT(e.what(), HasSubstr("from its port, outside the port's insertion [0.04, 0.2]"));
    }
    test::Rig ok = test::makeRig();
    ok.scene.laparoscope = scope(0);
    const std::unique_ptr<World> w = test::assemble(std::move(ok));
    ASSERT_NE(w->laparoscope(), nullptr);
    EXPECT_FALSE(w->laparoscope()->steering());
}
