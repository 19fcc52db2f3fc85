// The "suture" section (solver "fem") of scene.json and the World it assembles: features, strict
// parsing with messages naming the field, and only the declared subsystems created.
#include "sim/mesh/generators.hpp"
#include "sim/scene/scene.hpp"
#include "sim/scene/world.hpp"
#include "sim/suture/anastomosis.hpp"
#include "sim/util/error.hpp"

#include "suture_fixture.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

using namespace viscera::sim;
using ::testing::HasSubstr;

namespace {

std::string parseError(const std::string& text) {
    try {
        parseScene(text, "scene.json");
    } catch (const viscera::InputError& e) {
        return e.what();
    }
    return "accepted";
}

std::string withChange(const std::function<void(nlohmann::json&)>& change) {
    nlohmann::json j = nlohmann::json::parse(suture_fixture::kScene);
    change(j);
    return j.dump();
}

} // namespace

TEST(SutureScene, ParsesRoundTripsAndNamesItsFeatures) {
    const SceneDesc s = parseScene(suture_fixture::kScene, "scene.json");
    ASSERT_TRUE(s.suture);
    EXPECT_EQ(s.solverType, "fem");
    EXPECT_EQ(s.suture->settings.needle.shape, NeedleSpec::Shape::Straight);
    EXPECT_TRUE(s.suture->thread);
    EXPECT_FALSE(s.suture->contact);
    EXPECT_EQ(s.suture->trajectoryPath, "tools/needle.traj");
    EXPECT_EQ(requiredFeatures(s), (std::vector<std::string>{"fem", "needle", "thread"}));
    const SceneDesc again = parseScene(formatScene(s), "again.json");
    EXPECT_EQ(formatScene(again), formatScene(s));
    EXPECT_DOUBLE_EQ(again.suture->settings.needle.punctureForce, 0.005);
    EXPECT_DOUBLE_EQ(again.suture->settings.thread.slack, 0.001);
}

TEST(SutureScene, RejectsBadSectionsNamingTheField) {
    EXPECT_THAT(parseError(withChange([](auto& j) { j["suture"]["needle"]["shape"] = "hook"; })),
                HasSubstr("scene.json: suture.needle.shape: 'hook' is not a needle shape"));
    EXPECT_THAT(parseError(withChange([](auto& j) { j["suture"]["needle"]["radius"] = -1; })),
                HasSubstr("suture.needle.radius: must be positive"));
    EXPECT_THAT(parseError(withChange([](auto& j) { j["suture"].erase("trajectory"); })),
                HasSubstr("suture.trajectory: required"));
    EXPECT_THAT(parseError(withChange([](auto& j) {
                    j["suture"]["contact"] = {{"rounds", 99}};
                })),
                HasSubstr("suture.contact.rounds: must be an integer in [0, 16]"));
    EXPECT_THAT(parseError(withChange([](auto& j) {
                    j["suture"]["device"] = {{"pull_scale", 0}};
                })),
                HasSubstr("suture.device.pull_scale: must be in (0, 10]"));
    EXPECT_THAT(parseError(withChange([](auto& j) {
                    j["suture"]["device"] = {{"hand", 2}};
                })),
                HasSubstr("suture.device.hand: "));
    {
        const SceneDesc s = parseScene(withChange([](auto& j) {
                                           j["suture"]["device"] = {{"hand", "left"}};
                                       }),
                                       "d.json");
        EXPECT_TRUE(s.suture->device.declared);
        EXPECT_EQ(s.suture->device.hand, "left");
        EXPECT_EQ(formatScene(parseScene(formatScene(s), "again.json")), formatScene(s));
    }
    EXPECT_THAT(parseError(withChange([](auto& j) { j["suture"]["knot"] = 1; })),
                HasSubstr("suture.knot: unknown field"));
    EXPECT_THAT(parseError(withChange([](auto& j) { j.erase("suture"); })),
                HasSubstr("solver 'fem' needs a 'suture' section"));
    EXPECT_THAT(parseError(withChange([](auto& j) { j["solver"]["type"] = "xpbd"; })),
                HasSubstr("suture: needs solver.type 'fem'"));
    EXPECT_THAT(parseError(withChange([](auto& j) { j["solver"]["substeps"] = 3; })),
                HasSubstr("solver.substeps: unknown field"));
}

TEST(SutureScene, WorldCreatesOnlyTheDeclaredSubsystemsAndSteps) {
    SceneDesc s = parseScene(suture_fixture::kScene, "scene.json");
    s.suture->trajectoryText = suture_fixture::trajectory(40, 0.0007);
    // Undeclared feature: refused.
    EXPECT_THROW(World::assemble(s, suture_fixture::slabs(), {}, {"fem", "needle"}, "case: manifest.json"),
                 viscera::InputError);
    auto w = World::assemble(s, suture_fixture::slabs(), {}, {"fem", "needle", "thread"}, "case: manifest.json");
    ASSERT_TRUE(w->hasSuture());
    EXPECT_EQ(w->activeSubsystems(), (std::vector<std::string>{"fem", "needle", "thread"}));
    EXPECT_EQ(w->bodyCount(), 2u);
    for (int f = 0; f < 45; ++f)
        ASSERT_TRUE(w->step().finite) << f; // runs past the trajectory's end
    ASSERT_EQ(w->sutureFrames().size(), 45u);
    const SutureSummary sum = w->sutureSummary();
    EXPECT_GE(sum.punctures, 2); // through the upper slab at least
    EXPECT_TRUE(sum.gauge && sum.finite);
    EXPECT_NEAR(sum.initialGap, 0.001, 1e-9);
    EXPECT_TRUE(w->invariants().allFinite);
    // A broken trajectory and mismatched materials are load errors naming the rule.
    SceneDesc bad = s;
    bad.suture->trajectoryText = "0 0 0 1 0 0 0\n";
    try {
        World::assemble(bad, suture_fixture::slabs(), {}, {"fem", "needle", "thread"}, "case");
        FAIL() << "accepted";
    } catch (const viscera::InputError& e) {
        EXPECT_THAT(e.what(), HasSubstr("tools/needle.traj: line 1: expected 8 numbers"));
    }
    SceneDesc mixed = s;
    mixed.bodies[1].material.youngsModulus = 1000;
    try {
        World::assemble(mixed, suture_fixture::slabs(), {}, {"fem", "needle", "thread"}, "case");
        FAIL() << "accepted";
    } catch (const viscera::InputError& e) {
        EXPECT_THAT(e.what(), HasSubstr("all bodies need the same youngs_modulus and poisson_ratio"));
    }
}
