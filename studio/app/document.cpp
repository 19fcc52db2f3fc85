#include "app/document.hpp"
#include "app/value_command.hpp"

#include "bake/texture.hpp"

#include "render/sample_map.hpp"
#include "sim/material/material.hpp"
#include "sim/scene/scene_json.hpp"
#include "sim/skeleton/stiffness_paint.hpp"
#include "sim/util/error.hpp"
#include "sim/util/json_reader.hpp"

#include <QDir>
#include <QFileInfo>

#include <QUndoCommand>
#include <cmath>
#include <filesystem>

namespace viscera::studio {
namespace {

namespace fs = std::filesystem;

/// Moves the project's own file paths (imported meshes, the needle trajectory, instrument tracks)
/// from its folder to `to`, in the same layout, and makes `to` its folder. `moved` receives
/// (old, new) of each path. `strict` (Save As, which copies them): a path outside the folder
/// throws InputError naming it. Not strict (an undo step from before a Save As): a path outside
/// the folder, or one whose file was not copied to `to`, keeps naming the file that exists.
void rebaseProject(Project& p, const fs::path& to, std::vector<std::pair<fs::path, fs::path>>* moved, bool strict) {
    const fs::path from = p.dir.lexically_normal();
    auto relocate = [&](fs::path& f) {
        if (f.empty()) return;
        const fs::path rel = f.lexically_normal().lexically_relative(from);
        if (rel.empty() || *rel.begin() == "..") {
            if (strict) throw InputError(f.string() + ": is not inside the project folder " + p.dir.string());
            return;
        }
        std::error_code ec;
        if (!strict && !fs::exists(to / rel, ec)) return;
        if (moved) moved->emplace_back(f, to / rel);
        f = to / rel;
    };
    for (BodyProject& b : p.bodies) {
        if (b.mesh.kind == MeshSource::Kind::File) relocate(b.mesh.file);
        if (b.mesh.kind != MeshSource::Kind::Remesh) continue;
        for (RemeshSource::Part& part : b.mesh.remesh.parts)
            relocate(part.file);
        if (!b.mesh.remesh.texture.empty()) relocate(b.mesh.remesh.texture);
    }
    if (p.scene.suture && !p.trajectory.generator) relocate(p.trajectory.file);
    for (fs::path& t : p.trackFiles)
        relocate(t);
    p.dir = to;
}

} // namespace

/// One edit: the model before and after. Consecutive commands with the same nonzero key merge
/// (keeping the first `before`), so a drag of many mouse events is one undo step.
class ProjectCommand : public QUndoCommand {
public:
    ProjectCommand(Document* doc, const QString& text, Project before, Project after, int key, Change what)
        : QUndoCommand(text), m_doc(doc), m_before(std::move(before)), m_after(std::move(after)), m_key(key),
          m_what(what) {}
    int id() const override { return m_key ? 1 : -1; }
    bool mergeWith(const QUndoCommand* other) override {
        const auto* o = static_cast<const ProjectCommand*>(other);
        if (o->m_key != m_key) return false;
        m_after = o->m_after;
        m_what.parts |= o->m_what.parts;
        if (m_what.body != o->m_what.body) m_what.body = -1;
        return true;
    }
    void redo() override { m_doc->replace(m_after, m_what); }
    void undo() override { m_doc->replace(m_before, m_what); }

private:
    Document* m_doc;
    Project m_before, m_after;
    int m_key;
    Change m_what;
};

/// What a typed edit edits: the value's place in the model (`of`), what changing it announces and
/// the reader's rules for it (`check`: empty, or "<path>: <rule>").
struct MaterialSlot {
    using Value = sim::Material;
    static constexpr int kId = 2;
    static Value& of(Project& p, int body) { return p.bodies.at(static_cast<size_t>(body)).scene.material; }
    static Change change(int body) { return Change::material(body); }
    static std::string check(const Project& p, int body, const Value& m) {
        const std::string where = "bodies[" + std::to_string(body) + "].material: ";
        // readMaterial's check, then the constraint model with its curves (what check() builds)
        if (std::string why = sim::validate(m); !why.empty()) return where + why;
        try {
            sim::makeConstraintModel(m, p.bodies.at(static_cast<size_t>(body)).scene.name);
        } catch (const std::exception& e) {
            return where + e.what();
        }
        return {};
    }
};

struct SolverSlot {
    using Value = sim::XpbdSettings;
    static constexpr int kId = 3;
    static Value& of(Project& p, int) { return p.scene.xpbd; }
    static Change change(int) { return {Change::Solver, -1}; }
    static std::string check(const Project&, int, const Value& s) {
        const std::string why = sim::validate(s); // the limits readSolver applies (XpbdLimits)
        return why.empty() ? why : "solver: " + why;
    }
};

/// The case's assessment: the reader's rules on what the writer writes of it, and the reader's
/// measurability rule against the project's scene (every metric the scene cannot measure).
struct AssessmentSlot {
    using Value = std::optional<sim::AssessmentDesc>;
    static constexpr int kId = 6;
    static Value& of(Project& p, int) { return p.scene.assessment; }
    static Change change(int) { return {Change::Assessment, -1}; }
    static std::string check(const Project& p, int, const Value& a) {
        if (!a) return {};
        try {
            nlohmann::json doc;
            sim::writeAssessment(*a, doc);
            sim::readAssessment(sim::JsonField(doc["assessment"], "assessment", "project.json"));
        } catch (const std::exception& e) {
            const std::string why = e.what(); // "project.json: assessment...": editValue names the file
            return why.rfind("project.json: ", 0) == 0 ? why.substr(14) : why;
        }
        std::vector<std::string> bodies;
        for (const BodyProject& b : p.bodies)
            bodies.push_back(b.scene.name);
        std::string all;
        for (const std::string& why : sim::unmeasurableMetrics(*a, p.scene, bodies))
            all += (all.empty() ? "" : "; ") + why;
        return all;
    }
};

/// A body's stiffness paint (target >= 0) or surface -1 - target's.
struct PaintSlot {
    using Value = std::optional<StiffnessPaintProject>;
    static constexpr int kId = 4;
    static Value& of(Project& p, int t) {
        return t >= 0 ? p.bodies.at(static_cast<size_t>(t)).paint : p.surfaces.at(static_cast<size_t>(-1 - t)).paint;
    }
    static Change change(int t) { return {Change::Paint, t >= 0 ? t : -1}; }
    static std::string check(const Project&, int t, const Value& v) {
        if (!v) return {};
        const std::string where =
            (t >= 0 ? "bodies[" + std::to_string(t) : "surfaces[" + std::to_string(-1 - t)) + "].stiffness_paint";
        const sim::PaintParams& q = v->params;
        if (!(q.minWeight > 0 && q.minWeight <= q.baseWeight && q.baseWeight <= q.maxWeight &&
              std::isfinite(q.maxWeight)))
            return where + ": min_weight <= base_weight <= max_weight must hold";
        if (v->strokes.empty()) return where + ".strokes: must have at least 1 item";
        try { // readPaint's rule for every stroke
            for (size_t k = 0; k < v->strokes.size(); ++k)
                sim::validateStroke(v->strokes[k], k, where + ".strokes");
        } catch (const std::exception& e) {
            return e.what();
        }
        return {};
    }
};

struct LightSamplesSlot {
    using Value = std::vector<render::SamplePaintOp>;
    static constexpr int kId = 5;
    static Value& of(Project& p, int body) { return p.bodies.at(static_cast<size_t>(body)).lightSamples; }
    static Change change(int body) { return {Change::LightSamples, body}; }
    static std::string check(const Project&, int body, const Value& ops) {
        try { // readLightSamples' rules for every operation
            for (size_t k = 0; k < ops.size(); ++k) {
                const std::string where =
                    "bodies[" + std::to_string(body) + "].light_samples[" + std::to_string(k) + "]";
                if (!render::isSampleClass(ops[k].samples)) return where + ".samples: must be 0 (erase), 1, 4 or 8";
                const sim::NumberRule radius = sim::NumberRule::closed(kMinSampleBrushRadius, kMaxSampleBrushRadius);
                if (ops[k].tool == render::SamplePaintOp::Tool::Brush && !radius.admits(ops[k].radius))
                    return where + ".radius: " + radius.describe();
                render::validateSamplePaintOp(ops[k], where);
            }
        } catch (const std::exception& e) {
            return e.what();
        }
        return {};
    }
};

/// The placement of a body made from anatomy (its remesh block's unit, scale and rotation).
struct PlacementSlot {
    using Value = bake::ImportPlacement;
    static constexpr int kId = 7;
    static Value& of(Project& p, int body) { return p.bodies.at(static_cast<size_t>(body)).mesh.remesh.placement; }
    static Change change(int) { return {Change::Structure, -1}; }
    static std::string check(const Project&, int body, const Value& v) {
        return placementProblem(v, "bodies[" + std::to_string(body) + "].mesh.remesh"); // readRemesh's rule
    }
};

Document::Document(QObject* parent) : QObject(parent) {}
Document::~Document() = default;

void Document::replace(const Project& p, Change what) {
    // A model from before a Save As names the old folder: it is restored into the folder the
    // project lives in now (its files were copied there in the same layout).
    const fs::path here = m_project->dir;
    *m_project = p;
    if (m_project->dir != here) rebaseProject(*m_project, here, nullptr, false);
    ++m_revision;
    emit changed(what);
}

void Document::open(const QString& folder) {
    auto p = std::make_unique<Project>(loadProject(QDir(folder).absolutePath().toStdString()));
    m_undo.clear();
    m_project = std::move(p);
    m_folder = QDir(folder).absolutePath();
    ++m_revision;
    emit logMessage(tr("opened %1").arg(m_folder));
    emit changed(Change::everything());
}

void Document::createNew(const QString& folder, const QString& caseId) {
    const QString abs = QDir(folder).absolutePath();
    if (!QDir().mkpath(abs)) throw InputError(abs.toStdString() + ": the folder cannot be created");
    if (QFileInfo::exists(abs + "/project.json"))
        throw InputError((abs + "/project.json").toStdString() +
                         ": the folder already holds a project (open it instead)");
    Project p = newProject(abs.toStdString(), caseId.toStdString());
    saveProject(p, abs.toStdString());
    m_undo.clear();
    m_project = std::make_unique<Project>(std::move(p));
    m_folder = abs;
    ++m_revision;
    emit logMessage(tr("created %1").arg(abs));
    emit changed(Change::everything());
}

void Document::save() {
    if (!m_project) return;
    saveProject(*m_project, m_folder.toStdString());
    m_undo.setClean();
    emit logMessage(tr("saved %1/project.json").arg(m_folder));
}

void Document::saveAs(const QString& folder) {
    if (!m_project) return;
    const QString abs = QDir(folder).absolutePath();
    if (abs == m_folder) return save();
    if (!QDir().mkpath(abs)) throw InputError(abs.toStdString() + ": the folder cannot be created");
    // The project's files (imported meshes, trajectory, instrument tracks, texture specs) go along, in the same
    // layout, so that the saved project is complete; then project.json, atomically.
    Project p = *m_project;
    std::vector<std::pair<fs::path, fs::path>> copies;
    rebaseProject(p, abs.toStdString(), &copies, true);
    // texture specs (relative to the project folder) and the files they read travel too
    auto specOf = [&](const std::optional<TextureProject>& t) {
        if (!t) return;
        if (!t->generator.empty()) { // kept in project.json: only the files it reads
            std::vector<std::string> inputs;
            try {
                inputs = bake::specInputFiles(loadTextureBlock(*t, m_project->dir, "the texture generator"));
            } catch (const InputError&) { // the model's rules admitted it; a file may have gone since
            }
            for (const std::string& f : inputs)
                copies.emplace_back(m_project->dir / f, p.dir / f);
            return;
        }
        const fs::path spec = m_project->dir / t->spec;
        if (!fs::exists(spec)) return; // nothing to carry; export names the missing spec
        copies.emplace_back(spec, p.dir / t->spec);
        std::vector<std::string> inputs;
        try {
            inputs = bake::specInputFiles(bake::loadTextureSpec(spec));
        } catch (const InputError&) { // a broken spec is copied as it is, to be fixed there
        }
        for (const std::string& f : inputs)
            copies.emplace_back(spec.parent_path() / f, (p.dir / t->spec).parent_path() / f);
    };
    for (const BodyProject& b : p.bodies)
        specOf(b.texture);
    for (const SurfaceProject& sp : p.surfaces)
        specOf(sp.texture);
    for (const auto& [from, to] : copies) {
        std::error_code ec;
        fs::create_directories(to.parent_path(), ec);
        if (!ec && from != to) fs::copy_file(from, to, fs::copy_options::overwrite_existing, ec);
        if (ec) throw InputError(to.string() + ": cannot be written (" + ec.message() + ")");
    }
    saveProject(p, p.dir);
    *m_project = std::move(p);
    m_folder = abs;
    m_undo.setClean();
    emit logMessage(tr("saved %1/project.json").arg(abs));
    emit changed(Change::everything());
}

QString Document::check(const Project& p) {
    try {
        const std::string origin = (p.dir / "project.json").string();
        loadProjectText(projectJsonText(p), p.dir, origin);
        for (const BodyProject& b : p.bodies)
            sim::makeConstraintModel(b.scene.material, b.scene.name);
    } catch (const std::exception& e) {
        return QString::fromStdString(e.what());
    }
    return {};
}

QString Document::edit(const QString& text, const std::function<void(Project&)>& fn, int mergeKey, Change what) {
    if (!m_project) return tr("no project is open");
    Project after = *m_project;
    try {
        fn(after);
    } catch (const std::exception& e) {
        return QString::fromStdString(e.what());
    }
    if (QString why = check(after); !why.isEmpty()) return why;
    m_undo.push(new ProjectCommand(this, text, *m_project, std::move(after), mergeKey, what));
    return {};
}

QString Document::editMaterial(const QString& text, int body, const sim::Material& material, int mergeKey) {
    if (!m_project || body < 0 || body >= static_cast<int>(m_project->bodies.size())) return tr("no body selected");
    return editValue<MaterialSlot>(text, body, material, mergeKey);
}

QString Document::editSolver(const QString& text, const sim::XpbdSettings& settings) {
    return editValue<SolverSlot>(text, 0, settings, 0);
}

QString Document::editAssessment(const QString& text, const std::optional<sim::AssessmentDesc>& assessment) {
    const auto written = [](const std::optional<sim::AssessmentDesc>& a) {
        nlohmann::json doc = nlohmann::json::object();
        if (a) sim::writeAssessment(*a, doc);
        return doc;
    };
    if (m_project && written(m_project->scene.assessment) == written(assessment)) return {}; // no change, no step
    return editValue<AssessmentSlot>(text, 0, assessment, 0);
}

QString Document::editStiffnessPaint(const QString& text, int body, int surface,
                                     const std::optional<StiffnessPaintProject>& paint) {
    if (!m_project) return tr("no project is open");
    const bool isBody = body >= 0 && body < static_cast<int>(m_project->bodies.size());
    const bool isSurface = surface >= 0 && surface < static_cast<int>(m_project->surfaces.size());
    if (isBody == isSurface) return tr("paint a body or a surface");
    return editValue<PaintSlot>(text, isBody ? body : -1 - surface, paint, 0);
}

QString Document::editPlacement(const QString& text, int body, const bake::ImportPlacement& placement) {
    if (!m_project || body < 0 || body >= static_cast<int>(m_project->bodies.size())) return tr("no body selected");
    if (m_project->bodies[static_cast<size_t>(body)].mesh.kind != MeshSource::Kind::Remesh)
        return tr("%1: bodies[%2]: only a body made from anatomy has a unit, scale and rotation")
            .arg(QString::fromStdString((m_project->dir / "project.json").string()))
            .arg(body);
    return editValue<PlacementSlot>(text, body, placement, 0);
}

QString Document::editLightSamples(const QString& text, int body, const std::vector<render::SamplePaintOp>& ops) {
    if (!m_project || body < 0 || body >= static_cast<int>(m_project->bodies.size())) return tr("no body selected");
    return editValue<LightSamplesSlot>(text, body, ops, 0);
}

} // namespace viscera::studio
