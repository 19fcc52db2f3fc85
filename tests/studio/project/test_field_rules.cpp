// One rule per field: every numeric field of every sample's project.json, and of the scene.json the
// player reads, is fed wrong values (wrong type, non-finite, NaN, negative, out of range). Each
// refusal must be one line "<file>: <JSON path>: <rule>" naming that very field; a negative value
// may only pass where the quantity is signed (coordinates, gravity, curve points, ...).
#include "project/project.hpp"
#include "sim/scene/scene.hpp"
#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"
#include "support/scratch_dir.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <functional>
#include <set>

using namespace viscera;
using nlohmann::json;
using ::testing::HasSubstr;
using ::testing::StartsWith;

namespace {

const std::filesystem::path kProjects = std::filesystem::path(VISCERA_SOURCE_DIR) / "projects";
const std::vector<std::string> kSamples = {"tissue-slab", "organ-blob", "liver", "rectum", "anastomosis"};

/// Keys whose numbers may be negative (positions, directions, signed curve values, brush amplitude).
const std::set<std::string>
    kSigned = {"origin",   "center",    "start",  "end",      "min",      "max",  "gravity",
               "points",   "amplitude", "slack",  "lower",    "upper",    "axes", "needle_centre",
               "position", "tip",       "normal", "from_deg", "center_y", // ports, laparoscope, scenery and bend
               "line",     "point"};                                      // assessment targets

struct Leaf {
    json::json_pointer pointer;
    std::string path; ///< JSON path as messages write it: bodies[0].material.density
    std::string key;  ///< the innermost object key above the number
    bool integer = false;
};

void collect(const json& j, const json::json_pointer& ptr, const std::string& path, const std::string& key,
             std::vector<Leaf>& out) {
    if (j.is_object()) {
        for (auto it = j.begin(); it != j.end(); ++it)
            collect(it.value(), ptr / it.key(), path.empty() ? it.key() : path + "." + it.key(), it.key(), out);
    } else if (j.is_array()) {
        for (size_t i = 0; i < j.size(); ++i)
            collect(j[i], ptr / i, path + "[" + std::to_string(i) + "]", key, out);
    } else if (j.is_number()) {
        out.push_back({ptr, path, key, j.is_number_integer()});
    }
}

/// `text` with the number at `leaf` replaced by the raw JSON `raw`.
std::string withValue(const json& doc, const Leaf& leaf, const std::string& raw) {
    json copy = doc;
    const std::string marker = "\"@@value@@\"";
    copy[leaf.pointer] = "@@value@@";
    std::string text = copy.dump(1);
    text.replace(text.find(marker), marker.size(), raw);
    return text;
}

/// Feeds every numeric leaf of `doc` the wrong values; `read` parses a text and returns its
/// error ("accepted" when it passes). Returns the number of refusals checked.
int checkEveryNumber(const json& doc, const std::string& file,
                     const std::function<std::string(const std::string&)>& read) {
    std::vector<Leaf> leaves;
    collect(doc, json::json_pointer(), "", "", leaves);
    EXPECT_GT(leaves.size(), 5u) << file;
    int checked = 0;
    for (const Leaf& leaf : leaves) {
        SCOPED_TRACE(file + " " + leaf.path);
        // The field itself, or (for a rule between fields, "min must not exceed max") the object
        // that holds it.
        std::string element = leaf.path;
        while (element.back() == ']')
            element = element.substr(0, element.rfind('['));
        const size_t dot = element.rfind('.');
        const std::string holder = dot == std::string::npos ? std::string() : element.substr(0, dot);
        auto namesTheField = [&](const std::string& why) {
            for (const std::string& p : {leaf.path, element, holder})
                if (!p.empty() && why.rfind(file + ": " + p + ": ", 0) == 0) return true;
            return false;
        };
        const std::string prefix = file + ": " + leaf.path + ": ";
        const std::string fraction = read(withValue(doc, leaf, "2.5"));
        const bool integer = fraction == prefix + "must be an integer (found number)";
        if (fraction != "accepted") {
            EXPECT_TRUE(namesTheField(fraction)) << fraction;
        }
        EXPECT_EQ(read(withValue(doc, leaf, "\"7\"")),
                  prefix + (integer ? "must be an integer (found string)" : "must be a number (found string)"));
        EXPECT_EQ(read(withValue(doc, leaf, "null")),
                  prefix + (integer ? "must be an integer (found null)" : "must be a number (found null)"));
        // Not numbers JSON can carry: refused as a document, never read as inf or NaN.
        EXPECT_THAT(read(withValue(doc, leaf, "1e999")), StartsWith(file + ": invalid JSON ("));
        EXPECT_THAT(read(withValue(doc, leaf, "NaN")), StartsWith(file + ": invalid JSON ("));
        for (const char* raw : {"-5", "1e13", "1e308"}) {
            const std::string why = read(withValue(doc, leaf, raw));
            if (why == "accepted") {
                if (std::string(raw) == "-5") {
                    EXPECT_TRUE(kSigned.count(leaf.key)) << "a negative value passes";
                }
                continue;
            }
            EXPECT_TRUE(namesTheField(why)) << "value " << raw << ": " << why;
            EXPECT_EQ(why.find('\n'), std::string::npos);
            EXPECT_EQ(why.find("nan"), std::string::npos);
            ++checked;
        }
        checked += 4;
    }
    return checked;
}

class FieldRules : public ::testing::Test {
protected:
    /// Copies the sample to a fresh folder; returns its project.json document.
    json copySample(const std::string& name) {
        std::filesystem::remove_all(m_dir);
        std::filesystem::copy(kProjects / name, m_dir, std::filesystem::copy_options::recursive);
        return json::parse(readFile(m_dir / "project.json"));
    }
    std::string loadError(const std::string& text) {
        writeFileAtomic(m_dir / "project.json", text);
        try {
            studio::loadProject(m_dir);
        } catch (const InputError& e) {
            return e.what();
        }
        return "accepted";
    }
    test::Scratch m_scratch{"viscera-rules"};
    std::filesystem::path m_dir = m_scratch.dir / "project";
};

std::string sceneError(const std::string& text) {
    try {
        sim::parseScene(text, "scene.json");
    } catch (const InputError& e) {
        return e.what();
    }
    return "accepted";
}

/// The scene.json the player would read for a project (mesh paths and fixed nodes stand in for
/// what export computes from the meshes).
std::string sceneOf(const studio::Project& p) {
    sim::SceneDesc scene = p.scene;
    for (const studio::BodyProject& b : p.bodies) {
        sim::BodyDesc d = b.scene;
        d.meshPath = "meshes/" + d.name + ".vtet";
        d.fixedNodes = {0, 3};
        scene.bodies.push_back(d);
    }
    for (const studio::SurfaceProject& s : p.surfaces) {
        sim::SurfaceDesc d = s.scene;
        d.meshPath = "meshes/" + d.name + ".vtri";
        scene.surfaces.push_back(d);
    }
    return sim::formatScene(scene);
}

} // namespace

TEST_F(FieldRules, EveryNumberOfEverySampleProjectNamesItsPathAndRule) {
    int checked = 0;
    for (const std::string& sample : kSamples) {
        const json doc = copySample(sample);
        const std::string file = (m_dir / "project.json").string();
        ASSERT_EQ(loadError(doc.dump(1)), "accepted") << sample;
        checked += checkEveryNumber(doc, file, [&](const std::string& text) { return loadError(text); });
    }
    EXPECT_GT(checked, 400);
}

TEST_F(FieldRules, EveryNumberOfEverySampleSceneNamesItsPathAndRule) {
    int checked = 0;
    for (const std::string& sample : kSamples) {
        copySample(sample);
        const std::string text = sceneOf(studio::loadProject(m_dir));
        ASSERT_EQ(sceneError(text), "accepted") << sample;
        checked += checkEveryNumber(json::parse(text), "scene.json", sceneError);
    }
    EXPECT_GT(checked, 400);
}

TEST(FieldRulesScene, ToolsStrainLimitsAndNodeWeights) {
    sim::SceneDesc s;
    sim::BodyDesc b;
    b.name = "slab";
    b.meshPath = "meshes/slab.vtet";
    b.nodeWeights = {1.0, 2.0, 0.5};
    b.strainLimits = sim::TetStrainLimits{};
    b.strainLimits->limits.push_back({0, 0, -0.1, 0.2, 0.0});
    s.bodies.push_back(b);
    sim::ToolDesc t;
    t.name = "probe";
    s.tools.push_back(t);
    s.accuracy = sim::AccuracySampling{};
    const std::string text = sim::formatScene(s);
    ASSERT_EQ(sceneError(text), "accepted");
    EXPECT_GT(checkEveryNumber(json::parse(text), "scene.json", sceneError), 60);
}

TEST_F(FieldRules, NegativeStretchStiffnessIsRefusedAtLoadNotAtExport) {
    json doc = copySample("liver");
    doc["surfaces"][0]["stretch_stiffness"] = -5;
    EXPECT_EQ(loadError(doc.dump(1)),
              (m_dir / "project.json").string() + ": surfaces[0].stretch_stiffness: must not be negative");
    // The same field in the scene the player reads, by the same rule.
    doc["surfaces"][0]["stretch_stiffness"] = 50;
    writeFileAtomic(m_dir / "project.json", doc.dump(1));
    json scene = json::parse(sceneOf(studio::loadProject(m_dir)));
    scene["surfaces"][0]["stretch_stiffness"] = -5;
    EXPECT_EQ(sceneError(scene.dump()), "scene.json: surfaces[0].stretch_stiffness: must not be negative");
}

TEST_F(FieldRules, PaintWeightsAreOrderedAtLoad) {
    json doc = copySample("rectum");
    doc["bodies"][0]["stiffness_paint"]["min_weight"] = 2;
    EXPECT_EQ(loadError(doc.dump(1)),
              (m_dir / "project.json").string() +
                  ": bodies[0].stiffness_paint: min_weight <= base_weight <= max_weight must hold");
    doc["bodies"][0]["stiffness_paint"]["min_weight"] = 0.5;
    EXPECT_EQ(loadError(doc.dump(1)), "accepted");
}

TEST_F(FieldRules, BrushModesRoundTripAndBadModesNameTheRule) {
    json doc = copySample("rectum");
    json& strokes = doc["bodies"][0]["stiffness_paint"]["strokes"];
    const json first = strokes[0];
    json sub = first, mix = first, smooth = first;
    sub["mode"] = "subtract";
    mix["mode"] = "mix";
    mix["target"] = 3.5;
    mix["amplitude"] = 0.5;
    smooth["mode"] = "smooth";
    smooth["amplitude"] = 0.25;
    strokes.push_back(sub);
    strokes.push_back(mix);
    strokes.push_back(smooth);
    ASSERT_EQ(loadError(doc.dump(1)), "accepted");
    const studio::Project p = studio::loadProject(m_dir);
    const auto& s = p.bodies[0].paint->strokes;
    ASSERT_EQ(s.size(), strokes.size());
    EXPECT_EQ(s[s.size() - 3].mode, sim::BrushMode::Subtract);
    EXPECT_EQ(s[s.size() - 2].mode, sim::BrushMode::Mix);
    EXPECT_EQ(s[s.size() - 2].target, 3.5);
    EXPECT_EQ(s[s.size() - 1].mode, sim::BrushMode::Smooth);
    // written and read back, the model is the same
    const studio::Project again =
        studio::loadProjectText(studio::projectJsonText(p), m_dir, (m_dir / "project.json").string());
    EXPECT_EQ(studio::projectJsonText(again), studio::projectJsonText(p));
    const std::string where = (m_dir / "project.json").string() + ": bodies[0].stiffness_paint.strokes[";
    const std::string last = std::to_string(strokes.size() - 1);
    json bad = doc;
    bad["bodies"][0]["stiffness_paint"]["strokes"].back()["mode"] = "blur";
    EXPECT_THAT(loadError(bad.dump(1)), StartsWith(where + last + "].mode: "));
    bad = doc;
    bad["bodies"][0]["stiffness_paint"]["strokes"].back()["target"] = 2;
    EXPECT_EQ(loadError(bad.dump(1)), where + last + "].target: only a mix stroke has a target");
    bad = doc;
    bad["bodies"][0]["stiffness_paint"]["strokes"][strokes.size() - 2].erase("target");
    EXPECT_EQ(loadError(bad.dump(1)),
              where + std::to_string(strokes.size() - 2) + "].target: a mix stroke needs the weight it mixes towards");
    bad = doc;
    bad["bodies"][0]["stiffness_paint"]["strokes"].back()["amplitude"] = -1;
    EXPECT_THAT(loadError(bad.dump(1)), HasSubstr("a mix or smooth strength must be >= 0"));
}

TEST_F(FieldRules, BrushReachRoundTripsDefaultsToTheSkeletonAndBadValuesNameTheRule) {
    json doc = copySample("rectum");
    json& strokes = doc["bodies"][0]["stiffness_paint"]["strokes"];
    json sphere = strokes[0];
    sphere["reach"] = "sphere";
    strokes.push_back(sphere);
    ASSERT_EQ(loadError(doc.dump(1)), "accepted");
    const studio::Project p = studio::loadProject(m_dir);
    const auto& s = p.bodies[0].paint->strokes;
    EXPECT_EQ(s.front().reach, sim::BrushReach::Skeleton) << "a stroke without a reach: eq. 4.26 as before";
    EXPECT_EQ(s.back().reach, sim::BrushReach::Sphere);
    const std::string text = studio::projectJsonText(p);
    const studio::Project again = studio::loadProjectText(text, m_dir, (m_dir / "project.json").string());
    EXPECT_EQ(again.bodies[0].paint->strokes.back().reach, sim::BrushReach::Sphere);
    EXPECT_EQ(studio::projectJsonText(again), text);
    const std::string where = (m_dir / "project.json").string() + ": bodies[0].stiffness_paint.strokes[" +
                              std::to_string(strokes.size() - 1) + "].reach: ";
    json bad = doc;
    bad["bodies"][0]["stiffness_paint"]["strokes"].back()["reach"] = "everything";
    EXPECT_THAT(loadError(bad.dump(1)), StartsWith(where));
}

TEST_F(FieldRules, ProjectAndSceneShareTheRangeOfEverySharedField) {
    // A shared field refused in one file with a rule is refused in the other with the same rule.
    json doc = copySample("liver");
    writeFileAtomic(m_dir / "project.json", doc.dump(1));
    const json scene = json::parse(sceneOf(studio::loadProject(m_dir)));
    const std::vector<std::pair<std::string, std::string>> shared = {{"/solver/substeps", "0"},
                                                                     {"/solver/substeps", "1001"},
                                                                     {"/solver/dt", "0.5"},
                                                                     {"/solver/damping", "-1"},
                                                                     {"/bodies/0/material/poisson_ratio", "0.5"},
                                                                     {"/bodies/0/material/density", "0"},
                                                                     {"/bodies/1/embedding_compliance", "-1"},
                                                                     {"/surfaces/0/areal_density", "0"},
                                                                     {"/surfaces/0/attach_distance", "0"}};
    for (const auto& [pointer, raw] : shared) {
        SCOPED_TRACE(pointer + " = " + raw);
        json p = doc, s = scene;
        p[json::json_pointer(pointer)] = json::parse(raw);
        s[json::json_pointer(pointer)] = json::parse(raw);
        const std::string fromProject = loadError(p.dump());
        const std::string fromScene = sceneError(s.dump());
        ASSERT_THAT(fromScene, StartsWith("scene.json: "));
        EXPECT_EQ(fromProject, (m_dir / "project.json").string() + fromScene.substr(std::string("scene.json").size()));
    }
}
