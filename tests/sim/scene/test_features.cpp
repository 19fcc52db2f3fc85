// Manifest features: the names this build understands, what a scene needs, and the load checks.
#include "sim/scene/features.hpp"
#include "sim/util/error.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

using namespace viscera::sim;
using ::testing::HasSubstr;

namespace {
SceneDesc oneBody() {
    SceneDesc s;
    BodyDesc b;
    b.name = "slab";
    s.bodies.push_back(b);
    return s;
}
std::string declaredError(const SceneDesc& s, const std::vector<std::string>& f) {
    try {
        checkDeclaredFeatures(s, f, "c.vcase: manifest.json");
    } catch (const viscera::InputError& e) {
        return e.what();
    }
    return "accepted";
}
} // namespace

TEST(Features, SupportedAreSortedAndChecked) {
    const auto& f = supportedFeatures();
    EXPECT_TRUE(std::is_sorted(f.begin(), f.end()));
    EXPECT_NO_THROW(checkSupportedFeatures({"xpbd", "gravity"}, "c"));
    try {
        checkSupportedFeatures({"xpbd", "haptics"}, "c.vcase: manifest.json");
        FAIL() << "accepted";
    } catch (const viscera::InputError& e) {
        EXPECT_THAT(e.what(), HasSubstr("c.vcase: manifest.json: features: 'haptics' is not supported by this player "
                                        "(supported: accuracy, clip,"));
    }
}

TEST(Features, RequiredAndDeclared) {
    SceneDesc s = oneBody();
    EXPECT_EQ(requiredFeatures(s), (std::vector<std::string>{"gravity", "xpbd"}));
    EXPECT_EQ(checkDeclaredFeatures(s, {"xpbd", "gravity", "accuracy"}, "c"),
              (std::vector<std::string>{"gravity", "xpbd"}));
    EXPECT_EQ(declaredError(s, {"gravity"}),
              "c.vcase: manifest.json: features: the scene uses solver 'xpbd' but the manifest does not declare it");
    EXPECT_EQ(declaredError(s, {"xpbd"}),
              "c.vcase: manifest.json: features: the scene sets gravity but the manifest does not declare 'gravity'");
    s.accuracy = AccuracySampling{};
    EXPECT_EQ(declaredError(s, {"xpbd", "gravity"}),
              "c.vcase: manifest.json: features: the scene uses 'accuracy' but the manifest does not declare it");
}
