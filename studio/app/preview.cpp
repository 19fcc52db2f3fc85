#include "app/preview.hpp"

#include "sim/diagnostics/stability_check.hpp"
#include "sim/material/material.hpp"
#include "sim/scene/features.hpp"
#include "sim/scene/world.hpp"
#include "sim/scene/xpbd_scene_solver.hpp"
#include "sim/util/format.hpp"

#include <chrono>

#include <cmath>
#include <sys/resource.h>
#include <unistd.h>

namespace viscera::studio {
namespace {

using Clock = std::chrono::steady_clock;

/// The project text with every material replaced by the default one, no paint strokes or light
/// samples and default solver settings: equal keys mean that two models differ at most in what
/// applyMaterials() puts on the built meshes (materials, strokes through the skeletons already
/// made, solver settings) or what the view shows, so the meshes can be kept.
std::string structureKey(const Project& p, Preview::Mode mode, int body) {
    Project q = p;
    q.scene.xpbd = sim::XpbdSettings{};
    for (BodyProject& b : q.bodies) {
        b.scene.material = sim::Material{};
        b.fixedBoxes.clear(); // the holds go onto the meshes already built (applyMaterials)
        b.lightSamples.clear();
        if (b.paint) b.paint->strokes.clear();
    }
    for (SurfaceProject& sp : q.surfaces) {
        if (sp.paint) sp.paint->strokes.clear();
        sp.texture.reset();
    }
    for (BodyProject& b : q.bodies)
        b.texture.reset(); // material maps go onto the meshes already built (texturesKey)
    return projectJsonText(q) + (mode == Preview::Mode::Specimen ? "#specimen" : "#scene");
}

/// Everything but the material maps: when only those changed, the running world stays and only
/// the view is made again.
std::string allButTexturesKey(const Project& p, Preview::Mode mode) {
    Project q = p;
    for (BodyProject& b : q.bodies)
        b.texture.reset();
    for (SurfaceProject& sp : q.surfaces)
        sp.texture.reset();
    return projectJsonText(q) + (mode == Preview::Mode::Specimen ? "#specimen" : "#scene");
}

/// What the view's material maps are made from: every texture block with its spec's text (a
/// spec file edited elsewhere shows on the next change here).
std::string texturesKey(const Project& p) {
    std::string key;
    auto add = [&](const std::string& name, const std::optional<TextureProject>& t) {
        if (!t) return;
        key += name + "|" + sim::formatNumber(t->tilesPerMetre) + "|" + sim::formatNumber(t->normalStrength) + "|" +
               t->spec + "|";
        try {
            key += textureSpecText(*t, p.dir);
        } catch (const std::exception& e) {
            key += e.what();
        }
        key += '\n';
    };
    for (const BodyProject& b : p.bodies)
        add(b.scene.name, b.texture);
    for (const SurfaceProject& s : p.surfaces)
        add(s.scene.name, s.texture);
    return key;
}

/// The project's generated material maps on the view's meshes, as the exported case will show
/// them; a spec that cannot be read is reported and leaves the procedural look.
void applyTextures(const Project& project, render::SceneView& view) {
    const ProjectTextures t = bakeProjectTextures(project);
    auto read = [&t](const std::string& f) -> std::string_view {
        for (const auto& [path, bytes] : t.files)
            if (path == f) return bytes;
        return {};
    };
    for (const render::CaseMaterialMaps& m : t.materials)
        render::applyMaterialMaps(view, m.target, render::loadMaterialMaps(m, read, "the studio's texture bake"));
}

bool allFinite(const std::vector<sim::Vec3>& x) {
    for (const sim::Vec3& p : x)
        if (!p.allFinite()) return false;
    return true;
}

/// "body 'organ': stiffness number 0.21 at 110 substeps, needs at least 92" per XPBD body;
/// `ok` false when a body is over the limit.
QString stabilityVerdict(const BuiltScene& built, bool& ok) {
    ok = true;
    if (built.scene.solverType != "xpbd")
        return QObject::tr("solver %1: no XPBD stability rule").arg(QString::fromStdString(built.scene.solverType));
    QStringList lines;
    // the player's load rule: the scene as one system (embedded bodies count their ties' inertia)
    const std::string origin = "project.json";
    const std::vector<sim::StabilityFigures> figures =
        sim::assessSceneStability({built.scene, built.meshes, built.surfaces, origin});
    for (size_t i = 0; i < built.scene.bodies.size() && i < figures.size(); ++i) {
        const sim::BodyDesc& b = built.scene.bodies[i];
        const sim::StabilityFigures& f = figures[i];
        const QString head =
            QObject::tr("body '%1': stiffness number %2 (limit %3)")
                .arg(QString::fromStdString(b.name), QString::fromStdString(sim::formatNumber(f.maxStiffnessNumber, 3)),
                     QString::fromStdString(sim::formatNumber(sim::kMaxStiffnessNumber)));
        if (f.ok()) {
            lines << head + QObject::tr(": stable at %1 substeps (needs at least %2)")
                                .arg(built.scene.xpbd.substeps)
                                .arg(f.requiredSubsteps);
        } else {
            ok = false;
            lines << head + QObject::tr(": UNSTABLE at %1 substeps, needs at least %2 substeps")
                                .arg(built.scene.xpbd.substeps)
                                .arg(f.requiredSubsteps);
        }
    }
    return lines.join('\n');
}

/// Body `i` of `built` on its own (no layers, no embedding, no instruments) with accuracy
/// sampling on every frame: the Newton reference takes one tet body, so the error of a layered
/// scene is measured on the selected body's state without its couplings.
std::unique_ptr<sim::World> probeWorld(const BuiltScene& built, size_t i, const std::string& origin) {
    sim::SceneDesc scene;
    scene.solverType = built.scene.solverType;
    scene.xpbd = built.scene.xpbd;
    scene.xpbd.threads = 1;
    scene.bodies.push_back(built.scene.bodies.at(i));
    scene.bodies.back().embeddedIn.clear();
    scene.accuracy = sim::AccuracySampling{1, 100};
    std::vector<std::unique_ptr<sim::TetMesh>> meshes;
    meshes.push_back(built.meshes.at(i)->clone());
    return sim::World::assemble(scene, std::move(meshes), {}, sim::requiredFeatures(scene), origin);
}

} // namespace

Preview::Preview(QObject* parent) : QObject(parent) {}

Preview::~Preview() {
    stop();
}

void Preview::stop() {
    m_stop = true;
    m_wake.notify_all();
    {
        std::lock_guard lock(m_sampleMutex);
        m_sampleWake.notify_all();
    }
    if (m_thread.joinable()) m_thread.join();
    if (m_sampler.joinable()) m_sampler.join();
    m_sampleJob.reset();
    m_stop = false;
}

void Preview::sample() {
    // below the preview and the UI (nice 15): the reference solve may take much longer than a frame
    ::setpriority(PRIO_PROCESS, static_cast<id_t>(::gettid()), 15);
    while (!m_stop) {
        SampleJob job;
        {
            std::unique_lock lock(m_sampleMutex);
            m_sampleWake.wait(lock, [&] { return m_stop || m_sampleJob.has_value(); });
            if (m_stop) return;
            job = std::move(*m_sampleJob);
            m_sampleJob.reset();
            m_sampling = true;
        }
        std::optional<sim::AccuracyRecord> xpbd, newton;
        try {
            job.probe->clearAccuracy();
            job.probe->setState(0, job.x, job.v);
            job.probe->step();
            for (const sim::AccuracyRecord& a : job.probe->accuracy())
                (a.solver == "newton" ? newton : xpbd) = a;
        } catch (const std::exception& e) {
            emit logMessage(tr("preview: error sampling failed: %1").arg(QString::fromStdString(e.what())));
        }
        {
            std::lock_guard lock(m_mutex);
            if (xpbd && !xpbd->relError.empty()) {
                xpbd->frame = newton ? (newton->frame = job.frame) : job.frame;
                m_snapshot.accuracy = xpbd;
                m_snapshot.accuracyNewton = newton;
                ++m_revision;
            }
        }
        std::lock_guard lock(m_sampleMutex);
        m_sampling = false;
    }
}

uint64_t Preview::submit(const Project& project, Mode mode, int body, uint64_t* framesAtSubmit, Change what) {
    uint64_t serial;
    {
        std::lock_guard lock(m_mutex);
        serial = ++m_serial;
        if (framesAtSubmit) *framesAtSubmit = m_snapshot.frames;
        m_lastSubmitNs = Clock::now().time_since_epoch().count();
        // a model not taken yet is replaced; what it changed still counts
        if (m_pending) {
            what.parts |= m_pending->what.parts;
            if (what.body != m_pending->what.body) what.body = -1;
        }
        m_pending = Pending{project, mode, body, serial, what};
    }
    if (!m_thread.joinable()) m_thread = std::thread([this] { run(); });
    if (!m_sampler.joinable()) m_sampler = std::thread([this] { sample(); });
    m_wake.notify_all();
    return serial;
}

Preview::Snapshot Preview::snapshot() const {
    std::lock_guard lock(m_mutex);
    return m_snapshot;
}

std::shared_ptr<const sim::TetMesh> Preview::bodyMesh(int i) const {
    std::lock_guard lock(m_mutex);
    return i >= 0 && i < static_cast<int>(m_bodyMeshes.size()) ? m_bodyMeshes[i] : nullptr;
}

std::shared_ptr<const sim::TriMesh> Preview::surfaceMesh(int s) const {
    std::lock_guard lock(m_mutex);
    return s >= 0 && s < static_cast<int>(m_surfaceMeshes.size()) ? m_surfaceMeshes[s] : nullptr;
}

std::shared_ptr<const render::SceneView> Preview::sceneView() const {
    std::lock_guard lock(m_mutex);
    return m_view;
}

Project Preview::specimenProject(const Project& source, const sim::Material& material) {
    Project p;
    p.dir = source.dir;
    p.caseId = source.caseId.empty() ? "specimen" : source.caseId;
    p.caseVersion = source.caseVersion.empty() ? "1.0.0" : source.caseVersion;
    p.title = "Uniaxial specimen";
    if (source.scene.solverType == "xpbd") p.scene.xpbd = source.scene.xpbd;
    p.scene.xpbd.gravity = sim::Vec3(0, 0, -9.81);
    BodyProject b;
    b.scene.name = "specimen";
    b.scene.material = material;
    b.mesh.kind = MeshSource::Kind::Box;
    b.mesh.box.origin = sim::Vec3(-0.01, -0.01, -0.06);
    b.mesh.box.size = sim::Vec3(0.02, 0.02, 0.06);
    b.mesh.box.cells = {4, 4, 12};
    b.fixedBoxes = {std::array<sim::Vec3, 2>{sim::Vec3(-1, -1, -0.0001), sim::Vec3(1, 1, 1)}};
    p.bodies.push_back(std::move(b));
    return p;
}

/// The worker thread's state (run() and its parts only).
struct Preview::Worker {
    std::string builtKey, builtTextures, builtRest; ///< what the built meshes, maps and world were made from
    Mode builtMode = Mode::Scene;
    std::optional<BuiltScene> built;
    bool stale = false; ///< a general edit failed: `built` is not the submitted model's structure
    std::unique_ptr<sim::World> world;
    std::shared_ptr<sim::World> probe; ///< the selected body alone, for error sampling
    int probeBody = -1;
    uint64_t sceneRevision = 0, frames = 0;
    std::deque<double> history;
};

void Preview::run() {
    // The preview yields to the UI thread (nice 5): an editor stays responsive when the machine
    // is busy; the preview's frame rate gives way instead.
    ::setpriority(PRIO_PROCESS, static_cast<id_t>(::gettid()), 5);
    Worker w;
    while (!m_stop) {
        const auto frameStart = Clock::now();
        std::optional<Pending> job;
        uint64_t takenAfter = 0;
        {
            std::lock_guard lock(m_mutex);
            job.swap(m_pending);
            takenAfter = m_snapshot.frames;
        }
        if (job) takeJob(w, *job, takenAfter);
        if (!w.world || m_paused) {
            std::unique_lock lock(m_mutex);
            m_wake.wait_for(lock, std::chrono::milliseconds(50), [&] { return m_stop || m_pending.has_value(); });
            continue;
        }
        if (!stepFrame(w)) continue;
        emit frameReady();
        if (m_realTime && w.built) {
            const auto due = frameStart + std::chrono::duration<double>(w.built->scene.xpbd.dt);
            std::unique_lock lock(m_mutex);
            m_wake.wait_until(lock, due, [&] { return m_stop || m_pending.has_value(); });
        }
    }
}

void Preview::publishStatus(const std::function<void(Snapshot&)>& fn) {
    std::lock_guard lock(m_mutex);
    fn(m_snapshot);
    ++m_revision;
}

void Preview::takeJob(Worker& w, const Pending& job, uint64_t takenAfter) {
    if (job.mode == Mode::Scene && job.project.bodies.empty()) return showEmpty(w, job, takenAfter);
    Project project = job.project;
    if (job.mode == Mode::Specimen) {
        const int i = std::clamp(job.body, 0, std::max(0, static_cast<int>(project.bodies.size()) - 1));
        project =
            specimenProject(job.project, project.bodies.empty() ? sim::Material{} : project.bodies[i].scene.material);
    }
    const std::string origin = (project.dir / "project.json").string();
    try {
        // What changed decides (no project text is written): a typed edit of materials, paint
        // strokes or solver settings keeps the meshes; an edit of material maps or light-sample
        // paint keeps the running world; only a general edit compares the models, so that one
        // which leaves the meshes alone does not mesh the scene again.
        // (not after a general edit that failed: the meshes built are another model's)
        const bool same = w.built && w.world && job.mode == w.builtMode && !w.stale;
        const bool typed = same && job.what.only(Change::Material | Change::Paint | Change::Solver);
        const bool looks = same && job.what.only(Change::Texture | Change::LightSamples);
        std::string key, rest;
        if (!typed && !looks) {
            key = structureKey(project, job.mode, job.body);
            rest = allButTexturesKey(project, job.mode);
        }
        const bool mapsOnly = looks || (w.built && w.world && key == w.builtKey && rest == w.builtRest);
        if (mapsOnly) {
            showMaps(w, project, *w.world); // only material maps changed: the running world goes on
        } else {
            std::unique_ptr<sim::World> next;
            if (!typed && (!w.built || key != w.builtKey)) {
                next = buildWorld(w, project, job.mode, origin);
                w.builtKey = key;
            } else {
                next = applyMaterials(w, project, origin);
                // new material maps on the same meshes: a new view, without meshing again
                if (!typed && job.mode == Mode::Scene) showMaps(w, project, *next);
            }
            w.builtRest = rest; // empty after a typed edit: the next comparison applies the model again
            w.stale = false;
            w.world = std::move(next);
            makeProbe(w, job, origin);
        }
        const QString sampled = !w.probe ? tr("nothing (no XPBD body)")
                                : sim::supportsAccuracySampling(w.built->scene)
                                    ? tr("the scene")
                                    : tr("body '%1' alone (its layers are not coupled in the reference)")
                                          .arg(QString::fromStdString(w.built->scene.bodies[w.probeBody].name));
        publishStatus([&](Snapshot& s) {
            s.serial = job.serial;
            s.appliedAfter = takenAfter;
            s.accuracyOf = sampled;
            s.error.clear();
        });
    } catch (const std::exception& e) {
        const QString why = QString::fromStdString(e.what());
        publishStatus([&](Snapshot& s) {
            s.serial = job.serial; // seen, not shown
            // a general edit not shown leaves meshes of another model: no fast path until one is
            if (!job.what.only(Change::Material | Change::Paint | Change::Solver | Change::Texture |
                               Change::LightSamples))
                w.stale = true;
            s.appliedAfter = takenAfter;
            s.error = why;
        });
        emit logMessage(tr("preview: %1").arg(why));
        emit frameReady();
    }
}

namespace {

/// The project's scenery (anatomy around the working space, drawn only) in the preview's view,
/// as the player draws it.
void addProjectScenery(const Project& project, render::SceneView& view) {
    for (const SceneryProject& sp : project.scenery)
        render::addScenery(view, sp.name, scenerySurface(sp));
}

} // namespace

void Preview::showEmpty(Worker& w, const Pending& job, uint64_t takenAfter) {
    w.built.reset();
    w.world.reset();
    w.probe.reset();
    w.probeBody = -1;
    w.builtKey.clear();
    w.builtRest.clear();
    w.builtTextures.clear();
    w.stale = false;
    auto view = std::make_shared<render::SceneView>();
    addProjectScenery(job.project, *view);
    {
        std::lock_guard lock(m_mutex);
        m_view = std::move(view);
        m_bodyMeshes.clear();
        m_surfaceMeshes.clear();
        m_snapshot.scene = ++w.sceneRevision;
        m_snapshot.serial = job.serial;
        m_snapshot.appliedAfter = takenAfter;
        m_snapshot.frame = 0;
        m_snapshot.bodies.clear();
        m_snapshot.surfaces.clear();
        m_snapshot.verdict.clear();
        m_snapshot.verdictOk = true;
        m_snapshot.error.clear();
        m_snapshot.accuracyOf = tr("nothing (no body)");
        ++m_revision;
    }
    emit logMessage(tr("preview: no body yet (import anatomy or add a body)"));
    emit frameReady();
}

void Preview::showMaps(Worker& w, const Project& project, const sim::World& world) {
    std::string textures = texturesKey(project);
    if (textures == w.builtTextures) return;
    auto view = std::make_shared<render::SceneView>(render::SceneView::fromWorld(world));
    addProjectScenery(project, *view);
    try {
        applyTextures(project, *view);
    } catch (const std::exception& e) {
        emit logMessage(tr("preview: %1 (drawn without its material maps)").arg(e.what()));
    }
    w.builtTextures = std::move(textures);
    std::lock_guard lock(m_mutex);
    m_view = std::move(view);
    m_snapshot.scene = ++w.sceneRevision;
    ++m_revision;
}

std::unique_ptr<sim::World> Preview::buildWorld(Worker& w, const Project& project, Mode mode,
                                                const std::string& origin) {
    emit logMessage(tr("preview: building meshes"));
    BuiltScene b = buildScene(project);
    // one solver thread: the other core stays with the UI and the viewport's renderer
    b.scene.xpbd.threads = 1;
    bool ok = true;
    const QString verdict = stabilityVerdict(b, ok);
    publishStatus([&](Snapshot& s) {
        s.verdict = verdict;
        s.verdictOk = ok;
    });
    if (!ok) throw std::runtime_error(tr("the preview keeps the last stable model").toStdString());
    std::unique_ptr<sim::World> next = assembleWorld(b, origin);
    auto view = std::make_shared<render::SceneView>(render::SceneView::fromWorld(*next));
    if (mode == Mode::Scene) addProjectScenery(project, *view);
    if (mode == Mode::Scene && hasTextures(project)) {
        try {
            applyTextures(project, *view);
        } catch (const std::exception& e) { // the scene is still shown, procedural
            emit logMessage(tr("preview: %1 (drawn without its material maps)").arg(e.what()));
        }
    }
    std::vector<std::shared_ptr<const sim::TetMesh>> meshes;
    std::vector<std::shared_ptr<const sim::TriMesh>> surfaceMeshes;
    if (mode == Mode::Scene) {
        for (const auto& m : b.meshes)
            meshes.push_back(std::shared_ptr<const sim::TetMesh>(m->clone()));
        for (const sim::TriMesh& m : b.surfaces)
            surfaceMeshes.push_back(std::make_shared<const sim::TriMesh>(m));
    }
    w.built = std::move(b);
    w.builtMode = mode;
    w.builtTextures = texturesKey(project);
    {
        std::lock_guard lock(m_mutex);
        m_view = std::move(view);
        m_bodyMeshes = std::move(meshes);
        m_surfaceMeshes = std::move(surfaceMeshes);
        m_snapshot.scene = ++w.sceneRevision;
        ++m_revision;
    }
    emit logMessage(tr("preview: %1 bodies, %2 substeps per frame")
                        .arg(w.built->scene.bodies.size())
                        .arg(w.built->scene.xpbd.substeps));
    return next;
}

std::unique_ptr<sim::World> Preview::applyMaterials(Worker& w, const Project& project, const std::string& origin) {
    BuiltScene& b = *w.built;
    if (project.bodies.size() != b.scene.bodies.size() || project.surfaces.size() < b.scene.surfaces.size())
        throw std::runtime_error(tr("the meshes shown are another model's (%1 bodies, the project has %2)")
                                     .arg(b.scene.bodies.size())
                                     .arg(project.bodies.size())
                                     .toStdString());
    std::vector<sim::Material> old;
    std::vector<std::vector<double>> oldWeights, oldSurfaceWeights;
    std::vector<std::vector<int32_t>> oldFixed;
    auto restore = [&] {
        for (size_t i = 0; i < old.size(); ++i) {
            b.scene.bodies[i].material = old[i];
            b.scene.bodies[i].nodeWeights = oldWeights[i];
        }
        for (size_t i = 0; i < oldFixed.size(); ++i)
            b.scene.bodies[i].fixedNodes = oldFixed[i];
        for (size_t s = 0; s < oldSurfaceWeights.size(); ++s)
            b.scene.surfaces[s].nodeWeights = oldSurfaceWeights[s];
    };
    bool ok = true;
    QString verdict;
    std::unique_ptr<sim::World> next;
    const sim::XpbdSettings oldSolver = b.scene.xpbd;
    auto restoreAll = [&] {
        restore();
        b.scene.xpbd = oldSolver;
    };
    try {
        if (project.scene.solverType == b.scene.solverType) { // the solver settings too (one thread here)
            b.scene.xpbd = project.scene.xpbd;
            b.scene.xpbd.threads = 1;
        }
        for (size_t i = 0; i < b.scene.bodies.size(); ++i) {
            old.push_back(b.scene.bodies[i].material);
            oldWeights.push_back(b.scene.bodies[i].nodeWeights);
            oldFixed.push_back(b.scene.bodies[i].fixedNodes);
            b.scene.bodies[i].material = project.bodies[i].scene.material;
            // where it is held (the Hold tissue tool), on the mesh as the export reads it
            const sim::TetMesh& flat = i < b.flatMeshes.size() ? *b.flatMeshes[i] : *b.meshes[i];
            b.scene.bodies[i].fixedNodes =
                heldNodes(project.bodies[i], flat, origin, "bodies[" + std::to_string(i) + "]");
            // painted bodies: their strokes again, through the skeleton already made
            // (on the flat mesh where the project bends it: the strokes are placed there)
            if (project.bodies[i].paint && i < b.skeletons.size())
                b.scene.bodies[i].nodeWeights =
                    bodyNodeWeights(project.bodies[i], i < b.flatMeshes.size() ? *b.flatMeshes[i] : *b.meshes[i],
                                    b.skeletons[i], origin, "bodies[" + std::to_string(i) + "]");
        }
        for (size_t s = 0; s < b.scene.surfaces.size() && s < project.surfaces.size(); ++s) {
            oldSurfaceWeights.push_back(b.scene.surfaces[s].nodeWeights);
            if (project.surfaces[s].paint) // painted fascia: its strokes again
                b.scene.surfaces[s].nodeWeights = surfaceNodeWeights(
                    project.surfaces[s], s < b.flatSurfaces.size() ? b.flatSurfaces[s] : b.surfaces[s], origin,
                    "surfaces[" + std::to_string(s) + "]");
        }
        verdict = stabilityVerdict(b, ok);
        if (ok) next = assembleWorld(b, origin);
    } catch (...) {
        restoreAll();
        throw;
    }
    publishStatus([&](Snapshot& s) {
        s.verdict = verdict;
        s.verdictOk = ok;
    });
    if (!ok) {
        restoreAll();
        throw std::runtime_error(tr("the preview keeps the last stable material").toStdString());
    }
    if (w.world && w.world->bodyCount() == next->bodyCount() && w.world->surfaceCount() == next->surfaceCount() &&
        b.scene.solverType == "xpbd") {
        // the motion goes on under the new material (instruments restart their tracks)
        for (size_t i = 0; i < next->bodyCount(); ++i)
            next->setState(i, w.world->positions(i), w.world->velocities(i));
        for (size_t i = 0; i < next->surfaceCount(); ++i)
            next->setSurfaceState(i, w.world->surfacePositions(i), w.world->surfaceVelocities(i));
    }
    return next;
}

void Preview::makeProbe(Worker& w, const Pending& job, const std::string& origin) {
    w.probeBody = -1;
    w.probe.reset();
    if (w.built->scene.solverType != "xpbd" || w.built->scene.bodies.empty()) return;
    w.probeBody =
        std::clamp(job.mode == Mode::Specimen ? 0 : job.body, 0, static_cast<int>(w.built->scene.bodies.size()) - 1);
    try {
        w.probe = probeWorld(*w.built, static_cast<size_t>(w.probeBody), origin);
        w.probe->setAccuracyCancel(&m_stop); // stop() (closing, quitting) never waits for a reference
    } catch (const std::exception& e) {
        emit logMessage(
            tr("preview: no error sampling for body %1: %2").arg(w.probeBody).arg(QString::fromStdString(e.what())));
        w.probeBody = -1;
    }
}

bool Preview::stepFrame(Worker& w) {
    const sim::FrameRecord r = w.world->step();
    ++w.frames;
    bool finite = r.finite;
    for (size_t i = 0; finite && i < w.world->bodyCount(); ++i)
        finite = allFinite(w.world->positions(i));
    if (!finite) {
        emit logMessage(tr("preview: the state became non-finite at frame %1; restarting from rest").arg(r.index));
        try {
            w.world = assembleWorld(*w.built, "preview");
        } catch (const std::exception& e) {
            w.world.reset(); // shows nothing until the next model comes
            emit logMessage(tr("preview: %1").arg(QString::fromStdString(e.what())));
        }
        return false;
    }
    offerSample(w);
    w.history.push_back(r.stepMs);
    while (w.history.size() > kHistory)
        w.history.pop_front();
    std::lock_guard lock(m_mutex);
    Snapshot& s = m_snapshot;
    s.frame = r.index;
    s.frames = w.frames;
    s.stepMs = r.stepMs;
    s.frameMs = w.history;
    s.bodies.resize(w.world->bodyCount());
    for (size_t i = 0; i < w.world->bodyCount(); ++i)
        s.bodies[i] = w.world->positions(i);
    s.surfaces.resize(w.world->surfaceCount());
    for (size_t i = 0; i < w.world->surfaceCount(); ++i)
        s.surfaces[i] = w.world->surfacePositions(i);
    ++m_revision;
    return true;
}

void Preview::offerSample(Worker& w) {
    // Sampling waits for a quiet moment (no edit for kQuietMs): during a drag its reference
    // solve would take the core the UI and the preview need.
    const bool quiet = Clock::now().time_since_epoch().count() - m_lastSubmitNs.load() >
                       std::chrono::duration_cast<Clock::duration>(std::chrono::milliseconds(kQuietMs)).count();
    if (!w.probe || !quiet || w.frames < m_nextSample) return;
    // the selected body's state goes to the sampler thread, which solves the first substep from
    // it to convergence; the preview does not wait for it
    std::lock_guard lock(m_sampleMutex);
    if (m_sampleJob || m_sampling) return;
    const auto b = static_cast<size_t>(w.probeBody);
    m_sampleJob = SampleJob{w.probe, w.world->positions(b), w.world->velocities(b), static_cast<int>(w.frames)};
    m_nextSample = w.frames + static_cast<uint64_t>(std::max(1, m_accuracyEvery.load()));
    m_sampleWake.notify_all();
}

RealTimeEstimate estimateRealTime(const std::deque<double>& frameMs, double frameDt, size_t window, size_t minFrames) {
    RealTimeEstimate e;
    const size_t n = std::min(window, frameMs.size());
    if (n < std::max<size_t>(1, minFrames) || !(frameDt > 0)) return e;
    double sum = 0;
    for (size_t i = frameMs.size() - n; i < frameMs.size(); ++i)
        sum += frameMs[i];
    e.frames = static_cast<int>(n);
    e.meanMs = sum / static_cast<double>(n);
    e.budgetMs = 1e3 * frameDt;
    e.factor = e.meanMs > 0 ? e.budgetMs / e.meanMs : 0;
    return e;
}

} // namespace viscera::studio
