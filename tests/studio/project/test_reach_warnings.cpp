// The export's reach check [issue 57 item 1]: every shipped project's ports reach their task
// targets (no warning); a clip applier's port moved away gives one line naming project.json,
// the instrument, the target and the rule.
#include "project/project.hpp"
#include "support/scratch_dir.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>

using namespace viscera;
using ::testing::HasSubstr;

namespace {

std::filesystem::path sample(const std::string& name) {
    return std::filesystem::path(VISCERA_SOURCE_DIR) / "projects" / name;
}

} // namespace

TEST(ReachWarnings, EveryShippedProjectsPortsReachTheirTargets) {
    for (const char* name : {"tissue-slab", "organ-blob", "liver", "anastomosis", "rectum"})
        EXPECT_THAT(studio::reachWarnings(studio::loadProject(sample(name))), ::testing::IsEmpty()) << name;
}

TEST(ReachWarnings, APortThatCannotReachItsClipSiteIsNamed) {
    studio::Project p = studio::loadProject(sample("rectum"));
    auto& ins = p.scene.interaction->instruments;
    auto clipper = std::find_if(ins.begin(), ins.end(), [](const sim::InstrumentDesc& i) {
        return i.kind == sim::InstrumentDesc::Kind::ClipApplier;
    });
    ASSERT_NE(clipper, ins.end());
    clipper->port.maxAngleDeg = 1;
    // the rest tip (the track's first key) above the vessel; the site lies deeper than 1 mm past it
    clipper->port.insertionMax = clipper->port.insertionMin + 0.001;
    const std::vector<std::string> w = studio::reachWarnings(p);
    ASSERT_EQ(w.size(), 1u);
    EXPECT_THAT(w[0], HasSubstr("project.json: interaction.instruments["));
    EXPECT_THAT(w[0], HasSubstr("'" + clipper->name + "': its port cannot reach assessment.targets.clip[0] at ("));
    EXPECT_TRUE(w[0].find("insertion range") != std::string::npos || w[0].find("max_angle_deg") != std::string::npos)
        << w[0];
}
