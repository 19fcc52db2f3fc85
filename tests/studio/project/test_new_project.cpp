// Issue 57 item 7: File → New starts without a body (the model, its reader and writer accept
// one without; export and the scene build refuse it with one line), and export lists every
// assessment limit the scene cannot measure in its one error, not the first only.
#include "box_body.hpp"
#include "project/project.hpp"
#include "sim/scene/assessment.hpp"
#include "sim/util/error.hpp"
#include "support/scratch_dir.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

using namespace viscera;
using ::testing::HasSubstr;
namespace fs = std::filesystem;

namespace {

std::string messageOf(const std::function<void()>& fn) {
    try {
        fn();
    } catch (const std::exception& e) {
        return e.what();
    }
    return "(accepted)";
}

} // namespace

TEST(NewProject, StartsWithoutABodyAndIsReadAndWrittenAsItIs) {
    test::Scratch scratch("viscera-new-empty");
    const studio::Project p = studio::newProject(scratch.dir, "empty-case");
    EXPECT_TRUE(p.bodies.empty());
    EXPECT_TRUE(p.surfaces.empty());
    const std::string text = studio::projectJsonText(p);
    EXPECT_THAT(text, HasSubstr("\"bodies\": []"));
    const studio::Project back = studio::loadProjectText(text, scratch.dir, (scratch.dir / "project.json").string());
    EXPECT_TRUE(back.bodies.empty());
    EXPECT_EQ(studio::projectJsonText(back), text);
    studio::saveProject(p, scratch.dir);
    EXPECT_TRUE(studio::loadProject(scratch.dir).bodies.empty());
    // "bodies" itself is still required (a file without it is not a project)
    nlohmann::json without = nlohmann::json::parse(text);
    without.erase("bodies");
    EXPECT_EQ(messageOf([&] { studio::loadProjectText(without.dump(), scratch.dir, "p.json"); }),
              "p.json: bodies: required field is missing");
}

TEST(NewProject, ExportAndTheSceneBuildRefuseAProjectWithoutABody) {
    test::Scratch scratch("viscera-new-export");
    const studio::Project p = studio::newProject(scratch.dir, "empty-case");
    const std::string rule = (scratch.dir / "project.json").string() +
                             ": bodies: a case needs at least one body; import anatomy or add a body";
    EXPECT_EQ(messageOf([&] { studio::exportCase(p, scratch.dir / "empty.vcase"); }), rule);
    EXPECT_FALSE(fs::exists(scratch.dir / "empty.vcase")) << "nothing written";
    EXPECT_EQ(messageOf([&] { studio::buildScene(p); }), rule);
    studio::Project one = p;
    one.bodies.push_back(test::boxBody(sim::Vec3(0.04, 0.02, 0.02), {4, 2, 2}));
    EXPECT_EQ(studio::exportCase(one, scratch.dir / "one.vcase").bodies.size(), 1u);
}

TEST(AssessmentMeasurability, ExportListsEveryLimitTheSceneCannotMeasureInOneError) {
    test::Scratch scratch("viscera-unmeasurable");
    studio::Project p = studio::newProject(scratch.dir, "no-tools");
    p.bodies.push_back(test::boxBody(sim::Vec3(0.04, 0.02, 0.02), {4, 2, 2}));
    sim::AssessmentDesc a;
    // no laparoscope, no tool, no suture: none of these can be measured
    a.metrics = {{"path_length_m", 1.0, {}},
                 {"instrument_collisions", 0.0, {}},
                 {"out_of_view_s", 2.0, {}},
                 {"max_thread_tension_n", 3.0, {}}};
    const std::vector<std::string> problems = sim::unmeasurableMetrics(a, p.scene, {"tissue"});
    ASSERT_EQ(problems.size(), 4u);
    EXPECT_EQ(problems[0], "assessment.metrics.path_length_m: needs a tool (this scene has none: no session could "
                           "measure it)");
    EXPECT_THAT(problems[1], HasSubstr("assessment.metrics.instrument_collisions: needs two tools"));
    EXPECT_THAT(problems[2], HasSubstr("assessment.metrics.out_of_view_s: needs a laparoscope"));
    EXPECT_THAT(problems[3], HasSubstr("assessment.metrics.max_thread_tension_n: needs a suture"));
    p.scene.assessment = a;
    const std::string origin = (scratch.dir / "project.json").string();
    std::string expected = origin + ": ";
    for (size_t i = 0; i < problems.size(); ++i)
        expected += (i ? "; " : "") + problems[i];
    EXPECT_EQ(messageOf([&] { studio::exportCase(p, scratch.dir / "c.vcase"); }), expected);
    EXPECT_FALSE(fs::exists(scratch.dir / "c.vcase"));
    // the project reader applies the same rule, with the same list
    EXPECT_EQ(messageOf([&] { studio::loadProjectText(studio::projectJsonText(p), scratch.dir, origin); }), expected);
    // a vessel that is not a body is one more problem in the list
    a.vessel = sim::VesselTarget{"artery", 0.0015};
    EXPECT_EQ(sim::unmeasurableMetrics(a, p.scene, {"tissue"}).front(),
              "assessment.targets.vessel.body: 'artery' is not a body of the scene");
    a.vessel.reset();
    a.metrics = {{"completion_time_s", 5.0, {}}};
    a.cuts.push_back({{sim::Vec3(0, 0, 0), sim::Vec3(0.02, 0, 0)}, 0.005, 0.5});
    EXPECT_TRUE(sim::unmeasurableMetrics(a, p.scene, {"tissue"}).empty()) << "a measurable limit has no problem";
}
