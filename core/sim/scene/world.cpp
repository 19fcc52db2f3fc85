#include "sim/scene/world.hpp"

#include "sim/util/error.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace viscera::sim {

World::~World() = default;

void World::setState(size_t i, const std::vector<Vec3>& x, const std::vector<Vec3>& v) {
    if (i >= m_meshes.size()) throw std::invalid_argument("sim::World::setState(): no body " + std::to_string(i));
    m_solver->setState(i, x, v);
}

void World::setSurfaceState(size_t s, const std::vector<Vec3>& x, const std::vector<Vec3>& v) {
    if (s >= m_surfaces.size())
        throw std::invalid_argument("sim::World::setSurfaceState(): no surface " + std::to_string(s));
    m_solver->setSurfaceState(s, x, v);
}

void checkWorkBudget(const SceneDesc& scene, const std::vector<std::unique_ptr<TetMesh>>& meshes,
                     const std::vector<TriMesh>& surfaces, const std::string& origin) {
    if (scene.solverType != "xpbd") return;
    double elements = 0;
    for (const auto& m : meshes)
        elements += static_cast<double>(m->tetCount());
    for (const TriMesh& t : surfaces)
        elements += static_cast<double>(t.triangleCount());
    const double solves = double(scene.xpbd.substeps) * double(scene.xpbd.iterations) * elements;
    if (solves <= XpbdLimits::maxConstraintSolvesPerFrame) return;
    char text[256];
    std::snprintf(text, sizeof text,
                  ": solver: substeps %d x iterations %d x %.0f elements = %.3g constraint solves per frame, more "
                  "than the work limit of %.0e (about a second per frame); lower substeps or iterations",
                  scene.xpbd.substeps, scene.xpbd.iterations, elements, solves,
                  XpbdLimits::maxConstraintSolvesPerFrame);
    throw InputError(origin + text);
}

std::unique_ptr<World> World::assemble(const SceneDesc& scene, std::vector<std::unique_ptr<TetMesh>> meshes,
                                       std::vector<TriMesh> surfaces, const std::vector<std::string>& features,
                                       const std::string& origin) {
    checkSupportedFeatures(features, origin);
    if (meshes.size() != scene.bodies.size() || surfaces.size() != scene.surfaces.size())
        throw std::invalid_argument("sim::World::assemble(): one mesh per body and per surface is required");
    std::vector<std::string> needed = checkDeclaredFeatures(scene, features, origin);
    checkWorkBudget(scene, meshes, surfaces, origin);

    std::unique_ptr<World> w(new World());
    w->m_scene = scene;
    w->m_dt = scene.xpbd.dt;
    w->m_meshes = std::move(meshes);
    w->m_surfaces = std::move(surfaces);
    // The instruments collide with the first body's boundary when there is no fascia over it, and
    // with the boundary of the body the first fascia covers where it leaves it bare (bare_body).
    if (scene.interaction && w->m_surfaces.empty() && !w->m_meshes.empty()) w->m_meshes.front()->requireLevel(3);
    if (scene.interaction && scene.interaction->bareBody && !scene.surfaces.empty())
        for (size_t b = 0; b < scene.bodies.size() && b < w->m_meshes.size(); ++b)
            if (scene.bodies[b].name == scene.surfaces.front().attachTo) w->m_meshes[b]->requireLevel(3);
    w->m_solver = makeSceneSolver({w->m_scene, w->m_meshes, w->m_surfaces, origin});
    for (const BodyDesc& b : scene.bodies)
        w->m_names.push_back(b.name);
    if (!scene.tools.empty()) {
        std::vector<ToolProbes::Body> pb;
        for (size_t i = 0; i < scene.bodies.size(); ++i) {
            const Material& m = scene.bodies[i].material;
            pb.push_back({lumpedMasses(*w->m_meshes[i], m.density, scene.bodies[i].fixedNodes),
                          m.youngsModulus / (1 - m.poissonRatio * m.poissonRatio)});
            if (!scene.bodies[i].embeddedIn.empty()) pb.back().mass.assign(pb.back().mass.size(), 0.0);
        }
        w->m_probes = std::make_unique<ToolProbes>(scene.tools, std::move(pb), scene.xpbd.dt);
    }
    // Rules between a tool's rest tip and its port.
    for (size_t t = 0; t < scene.tools.size(); ++t)
        if (scene.tools[t].port.declared)
            if (const std::string why = restTipError(scene.tools[t].port, scene.tools[t].start); !why.empty())
                throw InputError(origin + ": tools[" + std::to_string(t) + "].start: " + why);
    if (scene.laparoscope) {
        if (const std::string why = restTipError(scene.laparoscope->port, scene.laparoscope->tip); !why.empty())
            throw InputError(origin + ": laparoscope.tip: " + why);
        w->m_scope = std::make_unique<Laparoscope>(*scene.laparoscope);
    }
    w->m_active = std::move(needed);
    w->m_invariants.maxEnergy = w->totalEnergy();
    return w;
}

void World::setAccuracyCancel(const std::atomic<bool>* flag) {
    m_solver->setAccuracyCancel(flag);
}

FrameRecord World::step() {
    const FrameClock clock{m_frame, m_time, m_dt};
    if (m_scene.accuracy && m_frame % m_scene.accuracy->everyFrames == 0) m_solver->sampleAccuracy(clock, m_accuracy);
    FrameRecord rec;
    rec.index = m_frame;
    const auto t0 = std::chrono::steady_clock::now();
    if (m_probes) applyTools(false);
    const StepStats st = m_solver->step(clock);
    if (m_probes) applyTools(true);
    rec.stepMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    rec.substeps = st.substeps;
    rec.iterations = st.iterations;
    rec.maxDisplacement = st.maxDisplacement;
    rec.finite = st.finite;
    m_invariants.speedClamps += st.speedClamps;
    rec.energy = totalEnergy();
    const bool figuresFinite = m_solver->recordFrame(clock);
    m_invariants.record(rec.finite && figuresFinite && std::isfinite(rec.energy), rec.energy, rec.maxDisplacement, 0.0);
    ++m_frame;
    m_time += m_dt;
    return rec;
}

void World::applyTools(bool measure) {
    std::vector<std::vector<Vec3>> x, v;
    for (size_t b = 0; b < m_meshes.size(); ++b) {
        x.push_back(m_solver->positions(b));
        v.push_back(m_solver->velocities(b));
    }
    const std::vector<char> changed = m_probes->apply(x, v, measure);
    try {
        for (size_t b = 0; b < changed.size(); ++b)
            if (changed[b]) m_solver->setState(b, x[b], v[b]);
    } catch (const std::invalid_argument&) { // non-finite state: the step's rollback handles it
    }
}

const std::vector<SutureFrameRecord>& World::sutureFrames() const {
    static const std::vector<SutureFrameRecord> none;
    const SutureReport* r = m_solver->suture();
    return r ? r->frames() : none;
}

SutureSummary World::sutureSummary() const {
    const SutureReport* r = m_solver->suture();
    if (!r) return {};
    SutureSummary s = r->summary();
    s.finite = s.finite && m_invariants.allFinite;
    return s;
}

} // namespace viscera::sim
