// The laparoscope and the task [issue 57]: typed edits of the scene, each checked by the scene
// reader's rule for its value (the value written by the scene writer and read back by the reader:
// no second copy of a rule).
#include "app/document.hpp"
#include "app/value_command.hpp"

#include "case/manifest.hpp"
#include "project/anatomy_shapes.hpp"
#include "sim/scene/scene_json.hpp"
#include "sim/scene/tool_probe.hpp"
#include "sim/util/json_reader.hpp"

#include <set>

namespace viscera::studio {
namespace {

/// "project.json: <path>: <rule>" → "<path>: <rule>" (editValue names the project's file).
std::string withoutOrigin(const std::exception& e) {
    const std::string why = e.what();
    return why.rfind("project.json: ", 0) == 0 ? why.substr(14) : why;
}

/// The case's laparoscope: readLaparoscope on what writeLaparoscope writes, then the rest tip
/// within the port's insertion (World::assemble's rule), then every assessment metric still
/// measurable (out_of_view_s needs a scope).
struct LaparoscopeSlot {
    using Value = std::optional<sim::LaparoscopeDesc>;
    static constexpr int kId = 8;
    static Value& of(Project& p, int) { return p.scene.laparoscope; }
    static Change change(int) { return {Change::Scene, -1}; }
    static std::string check(const Project& p, int, const Value& v) {
        try {
            if (v) {
                nlohmann::json doc;
                sim::writeLaparoscope(*v, doc);
                const sim::LaparoscopeDesc back =
                    sim::readLaparoscope(sim::JsonField(doc["laparoscope"], "laparoscope", "project.json"));
                if (const std::string why = sim::restTipError(back.port, back.tip); !why.empty())
                    return "laparoscope.tip: " + why;
            }
            sim::SceneDesc scene = p.scene;
            scene.laparoscope = v;
            std::vector<std::string> bodies;
            for (const BodyProject& b : p.bodies)
                bodies.push_back(b.scene.name);
            sim::checkAssessmentMeasurable(scene, bodies, "project.json");
        } catch (const std::exception& e) {
            return withoutOrigin(e);
        }
        return {};
    }
};

/// The task shown to the trainee: the case title, the instructions and the ordered steps.
struct Task {
    std::string title, instructions;
    std::vector<std::string> steps;
};

/// The task's three fields live in Project::title and scene.instructions / scene.steps: a view of
/// them that reads and writes as one value, so that ValueCommand holds only the old and new task.
struct TaskView {
    Project& p;
    operator Task() const { return {p.title, p.scene.instructions, p.scene.steps}; }
    TaskView& operator=(const Task& t) {
        p.title = t.title;
        p.scene.instructions = t.instructions;
        p.scene.steps = t.steps;
        return *this;
    }
};

struct TaskSlot {
    using Value = Task;
    static constexpr int kId = 9;
    static TaskView of(Project& p, int) { return {p}; }
    static Change change(int) { return {Change::Scene, -1}; }
    static std::string check(const Project&, int, const Value& t) {
        try { // the readers' rules: the manifest's title, the scene's instructions and steps
            nlohmann::json doc = {{"title", t.title}, {"instructions", t.instructions}};
            sim::writeSteps(t.steps, doc);
            const std::string origin = "project.json"; // JsonField keeps a pointer to it
            const sim::JsonField root(doc, "", origin);
            root["title"].displayText(vcase::kMaxTitleBytes);
            root["instructions"].displayText(sim::kMaxInstructionsBytes);
            if (auto s = root.find("steps")) sim::readSteps(*s);
        } catch (const std::exception& e) {
            return withoutOrigin(e);
        }
        return {};
    }
};

/// The surroundings [issue 57 item 1]: the render-only scenery primitives with their textures,
/// one value (the textures stay one per primitive). Checked by the project reader's rule for
/// "scenery" (readSceneryProject on what sceneryJson writes), its names new among the bodies,
/// surfaces and probes as at load.
struct Surroundings {
    std::vector<SceneryProject> scenery;
    std::vector<std::optional<TextureProject>> textures;
};

struct SurroundingsView {
    Project& p;
    operator Surroundings() const { return {p.scenery, p.sceneryTextures}; }
    SurroundingsView& operator=(const Surroundings& s) {
        p.scenery = s.scenery;
        p.sceneryTextures = s.textures;
        return *this;
    }
};

struct SurroundingsSlot {
    using Value = Surroundings;
    static constexpr int kId = 10;
    static SurroundingsView of(Project& p, int) { return {p}; }
    static Change change(int) { return {Change::Structure, -1}; }
    static std::string check(const Project& p, int, const Value& v) {
        if (v.textures.size() != v.scenery.size()) return "scenery: a texture slot per surrounding is missing";
        if (v.scenery.empty()) return {};
        try {
            std::set<std::string> names;
            for (const BodyProject& b : p.bodies)
                names.insert(b.scene.name);
            for (const SurfaceProject& sp : p.surfaces)
                names.insert(sp.scene.name);
            for (const sim::ToolDesc& t : p.scene.tools)
                names.insert(t.name);
            const nlohmann::json doc = sceneryJson(v.scenery, p.dir);
            const std::string origin = "project.json"; // JsonField keeps a pointer to it
            readSceneryProject(sim::JsonField(doc, "scenery", origin), names, p.dir);
        } catch (const std::exception& e) {
            return withoutOrigin(e);
        }
        return {};
    }
};

} // namespace

QString Document::editScenery(const QString& text, const std::vector<SceneryProject>& scenery,
                              const std::vector<std::optional<TextureProject>>& textures, int mergeKey) {
    return editValue<SurroundingsSlot>(text, 0, Surroundings{scenery, textures}, mergeKey);
}

QString Document::editLaparoscope(const QString& text, const std::optional<sim::LaparoscopeDesc>& value, int mergeKey) {
    return editValue<LaparoscopeSlot>(text, 0, value, mergeKey);
}

QString Document::editTask(const QString& text, const std::string& title, const std::string& instructions,
                           const std::vector<std::string>& steps) {
    return editValue<TaskSlot>(text, 0, Task{title, instructions, steps}, 0);
}

} // namespace viscera::studio
