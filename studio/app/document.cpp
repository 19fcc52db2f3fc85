#include "app/document.hpp"

#include "bake/texture.hpp"

#include "sim/material/material.hpp"
#include "sim/util/error.hpp"

#include <QDir>
#include <QFileInfo>

#include <QUndoCommand>
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
    for (BodyProject& b : p.bodies)
        if (b.mesh.kind == MeshSource::Kind::File) relocate(b.mesh.file);
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

/// A typed edit of one body's material: the material before and after, nothing else. A drag
/// (the same nonzero key) merges into one step, keeping the first `before`.
class MaterialCommand : public QUndoCommand {
public:
    MaterialCommand(Document* doc, const QString& text, int body, sim::Material before, sim::Material after, int key)
        : QUndoCommand(text), m_doc(doc), m_body(body), m_before(std::move(before)), m_after(std::move(after)),
          m_key(key) {}
    int id() const override { return m_key ? 2 : -1; }
    bool mergeWith(const QUndoCommand* other) override {
        const auto* o = static_cast<const MaterialCommand*>(other);
        if (o->m_key != m_key || o->m_body != m_body) return false;
        m_after = o->m_after;
        return true;
    }
    void redo() override { m_doc->setMaterial(m_body, m_after); }
    void undo() override { m_doc->setMaterial(m_body, m_before); }

private:
    Document* m_doc;
    int m_body;
    sim::Material m_before, m_after;
    int m_key;
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

void Document::setMaterial(int body, const sim::Material& m) {
    m_project->bodies.at(static_cast<size_t>(body)).scene.material = m;
    ++m_revision;
    emit changed(Change::material(body));
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
    if (!m_project) return tr("no project is open");
    if (body < 0 || body >= static_cast<int>(m_project->bodies.size())) return tr("no body selected");
    const BodyProject& b = m_project->bodies[static_cast<size_t>(body)];
    const std::string where =
        (m_project->dir / "project.json").string() + ": bodies[" + std::to_string(body) + "].material: ";
    // The reader's rules for a material value: sim::validate (readMaterial's check) and the
    // constraint model with its curves (what check() builds for every body).
    if (const std::string why = sim::validate(material); !why.empty()) return QString::fromStdString(where + why);
    try {
        sim::makeConstraintModel(material, b.scene.name);
    } catch (const std::exception& e) {
        return QString::fromStdString(where + e.what());
    }
    m_undo.push(new MaterialCommand(this, text, body, b.scene.material, material, mergeKey));
    return {};
}

} // namespace viscera::studio
