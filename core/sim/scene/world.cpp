#include "sim/scene/world.hpp"

#include "sim/diagnostics/stability_check.hpp"
#include "sim/reference/accuracy.hpp"
#include "sim/util/error.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace viscera::sim {
namespace {
const char* kXpbd = "xpbd";
const char* kGravity = "gravity";
const char* kFascia = "fascia";
const char* kEmbedding = "embedding";
const char* kStrainLimit = "strain_limit";
const char* kAccuracy = "accuracy";
const char* kProbe = "probe";
const char* kFem = "fem";
const char* kNeedle = "needle";
const char* kThread = "thread";
const char* kContact = "contact";
const char* kCollision = "collision";
const char* kDissection = "dissection";
const char* kClip = "clip";

bool has(const std::vector<std::string>& v, const std::string& x) { return std::find(v.begin(), v.end(), x) != v.end(); }

std::string stripPrefix(std::string why) {
    for (const char* prefix : {"sim::XpbdSolver::create(): ", "sim::XpbdSystem::create(): "})
        if (why.rfind(prefix, 0) == 0) return why.substr(std::char_traits<char>::length(prefix));
    return why;
}
} // namespace

const std::vector<std::string>& supportedFeatures() {
    static const std::vector<std::string> f = {kAccuracy, kClip,   kCollision,   kContact, kDissection, kEmbedding,
                                               kFascia,   kFem,    kGravity,     kNeedle,  kProbe,      kStrainLimit,
                                               kThread,   kXpbd};
    return f;
}

std::vector<std::string> requiredFeatures(const SceneDesc& scene) {
    std::vector<std::string> f;
    if (!scene.bodies.empty()) f.push_back(scene.solverType);
    if (scene.xpbd.gravity.squaredNorm() > 0) f.push_back(kGravity);
    if (!scene.surfaces.empty()) f.push_back(kFascia);
    for (const auto& b : scene.bodies) {
        if (!b.embeddedIn.empty() && !has(f, kEmbedding)) f.push_back(kEmbedding);
        if (b.strainLimits && !has(f, kStrainLimit)) f.push_back(kStrainLimit);
    }
    if (scene.accuracy) f.push_back(kAccuracy);
    if (!scene.tools.empty()) f.push_back(kProbe);
    if (scene.interaction) {
        using K = InstrumentDesc::Kind;
        if (scene.interaction->has(K::Grasper) || scene.interaction->has(K::EnergyHook)) f.push_back(kCollision);
        if (scene.interaction->has(K::EnergyHook)) f.push_back(kDissection);
        if (scene.interaction->has(K::ClipApplier)) f.push_back(kClip);
    }
    if (scene.suture) {
        f.push_back(kNeedle);
        if (scene.suture->thread) f.push_back(kThread);
        if (scene.suture->contact) f.push_back(kContact);
    }
    std::sort(f.begin(), f.end());
    return f;
}

World::~World() = default;

std::unique_ptr<World> World::assemble(const SceneDesc& scene, std::vector<std::unique_ptr<TetMesh>> meshes,
                                       std::vector<TriMesh> surfaces, const std::vector<std::string>& features,
                                       const std::string& origin) {
    std::string list;
    for (const auto& s : supportedFeatures()) list += (list.empty() ? "" : ", ") + s;
    for (const std::string& f : features)
        if (!has(supportedFeatures(), f))
            throw InputError(origin + ": features: '" + f + "' is not supported by this player (supported: " + list + ")");
    if (meshes.size() != scene.bodies.size() || surfaces.size() != scene.surfaces.size())
        throw std::invalid_argument("sim::World::assemble(): one mesh per body and per surface is required");
    const std::vector<std::string> needed = requiredFeatures(scene);
    for (const std::string& f : needed)
        if (!has(features, f)) {
            if (f == scene.solverType)
                throw InputError(origin + ": features: the scene uses solver '" + f + "' but the manifest does not declare it");
            if (f == kGravity)
                throw InputError(origin + ": features: the scene sets gravity but the manifest does not declare 'gravity'");
            throw InputError(origin + ": features: the scene uses '" + f + "' but the manifest does not declare it");
        }
    if (scene.solverType == kFem) return assembleSuture(scene, std::move(meshes), needed, origin);
    const bool layered = !scene.surfaces.empty() || scene.bodies.size() > 1 || scene.interaction.has_value();
    if (scene.accuracy && layered)
        throw InputError(origin + ": features: 'accuracy' sampling needs a scene with a single tet body and no layers");

    if (auto why = validate(scene.xpbd); !why.empty())
        throw InputError(origin + ": scene cannot be simulated stably: solver: " + why);
    std::unique_ptr<World> w(new World());
    w->m_scene = scene;
    w->m_dt = scene.xpbd.dt;
    XpbdSystemDesc desc;
    for (size_t i = 0; i < scene.bodies.size(); ++i) {
        const BodyDesc& b = scene.bodies[i];
        TetBodyDesc tb;
        tb.name = b.name;
        tb.mesh = meshes[i].get();
        tb.model = makeConstraintModel(b.material, b.name); // InputError names material and curve
        tb.density = b.material.density;
        tb.fixedNodes = b.fixedNodes;
        tb.nodeWeights = b.nodeWeights;
        tb.strainLimits = b.strainLimits;
        if (tb.nodeWeights.empty() || tb.nodeWeights.size() == meshes[i]->vertexCount()) {
            const StabilityFigures fig = assessStability(*meshes[i], *tb.model, tb.density, tb.nodeWeights, scene.xpbd);
            if (auto why = stabilityProblem(b.name, fig, scene.xpbd); !why.empty())
                throw InputError(origin + ": scene cannot be simulated stably: " + why);
        }
        desc.tetBodies.push_back(std::move(tb));
        w->m_names.push_back(b.name);
    }
    auto bodyIndex = [&](const std::string& name) {
        for (size_t i = 0; i < scene.bodies.size(); ++i)
            if (scene.bodies[i].name == name) return i;
        return size_t(0);
    };
    for (size_t i = 0; i < scene.bodies.size(); ++i)
        if (!scene.bodies[i].embeddedIn.empty()) {
            EmbeddingDesc e;
            e.embedded = i;
            e.cage = bodyIndex(scene.bodies[i].embeddedIn);
            e.compliance = scene.bodies[i].embeddingCompliance;
            desc.embeddings.push_back(e);
        }
    for (size_t s = 0; s < scene.surfaces.size(); ++s) {
        const SurfaceDesc& sd = scene.surfaces[s];
        SurfaceBodyDesc sb;
        sb.name = sd.name;
        sb.mesh = &surfaces[s];
        sb.arealDensity = sd.arealDensity;
        sb.stretchStiffness = sd.stretchStiffness;
        sb.fixedNodes = sd.fixedNodes;
        desc.surfaces.push_back(std::move(sb));
        if (!sd.attachTo.empty()) {
            SurfaceAttachmentDesc a;
            a.surface = s;
            a.tetBody = bodyIndex(sd.attachTo);
            a.maxDistance = sd.attachDistance;
            a.compliance = sd.attachCompliance;
            desc.attachments.push_back(a);
        }
    }
    try {
        if (layered)
            w->m_system = XpbdSystem::create(desc, scene.xpbd);
        else
            w->m_single = XpbdSolver::create(desc.tetBodies.front(), scene.xpbd);
    } catch (const std::invalid_argument& e) {
        throw InputError(origin + ": scene cannot be simulated stably: " + stripPrefix(e.what()));
    }
    w->m_meshes = std::move(meshes);
    w->m_surfaces = std::move(surfaces);
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
    if (scene.interaction) {
        std::vector<const TetMesh*> bodies;
        for (const auto& m : w->m_meshes) bodies.push_back(m.get());
        std::vector<const TriMesh*> layers;
        for (const TriMesh& m : w->m_surfaces) layers.push_back(&m);
        w->m_interaction = InteractionRuntime::create(scene, *w->m_system, bodies, layers, origin);
    }
    w->m_active = needed;
    w->m_invariants.maxEnergy = w->totalEnergy();
    return w;
}

const std::vector<Vec3>& World::positions(size_t i) const {
    if (m_suture) return m_bodyX[i];
    return m_single ? m_single->positions() : m_system->tetPositions(i);
}

const std::vector<Vec3>& World::surfacePositions(size_t s) const { return m_system->surfacePositions(s); }

double World::totalEnergy() const {
    if (m_suture) return m_suture->fem().elasticEnergy();
    if (m_single) return m_single->elasticEnergy() + m_single->kineticEnergy() + m_single->potentialEnergy();
    return m_system->elasticEnergy() + m_system->kineticEnergy() + m_system->potentialEnergy();
}

void World::measureAccuracy() {
    // Never throws from the per-frame path: a failed measurement is recorded as empty traces.
    auto keep = [&](AccuracyTrace t) {
        AccuracyRecord r;
        r.frame = m_frame;
        r.solver = t.solver;
        r.iterations = std::move(t.iterations);
        r.relError = std::move(t.relError);
        r.timeMs = std::move(t.timeMs);
        m_accuracy.push_back(std::move(r));
    };
    try {
        keep(measureXpbd(*m_single, m_scene.accuracy->maxIterations, {},
                         m_scene.xpbd.primalCorrection ? XpbdIteration::PrimalCorrected
                                                       : XpbdIteration::Standard));
        keep(measureNewton(*m_single));
    } catch (const std::exception&) {
        AccuracyRecord r;
        r.frame = m_frame;
        r.solver = "xpbd";
        m_accuracy.push_back(std::move(r));
    }
}

FrameRecord World::step() {
    if (m_suture) return stepSuture();
    if (m_scene.accuracy && m_single && m_frame % m_scene.accuracy->everyFrames == 0) measureAccuracy();
    FrameRecord rec;
    rec.index = m_frame;
    const auto t0 = std::chrono::steady_clock::now();
    if (m_probes) applyTools(false);
    if (m_interaction) m_interaction->beforeStep(m_time + m_dt, m_dt);
    const StepStats st = m_single ? m_single->step() : m_system->step();
    if (m_interaction) m_interaction->afterStep();
    if (m_probes) applyTools(true);
    rec.stepMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    rec.substeps = st.substeps;
    rec.iterations = st.iterations;
    rec.maxDisplacement = st.maxDisplacement;
    rec.finite = st.finite;
    m_invariants.speedClamps += st.speedClamps;
    rec.energy = totalEnergy();
    m_invariants.record(rec.finite && std::isfinite(rec.energy), rec.energy, rec.maxDisplacement, 0.0);
    ++m_frame;
    m_time += m_dt;
    return rec;
}

void World::applyTools(bool measure) {
    std::vector<std::vector<Vec3>> x, v;
    for (size_t b = 0; b < m_meshes.size(); ++b) {
        x.push_back(positions(b));
        v.push_back(m_single ? m_single->velocities() : m_system->tetVelocities(b));
    }
    const std::vector<char> changed = m_probes->apply(x, v, measure);
    try {
        for (size_t b = 0; b < changed.size(); ++b)
            if (changed[b]) m_single ? m_single->setState(x[b], v[b]) : m_system->setTetState(b, x[b], v[b]);
    } catch (const std::invalid_argument&) { // non-finite state: the step's rollback handles it
    }
}

// ---- suturing ---------------------------------------------------------------------------------

std::unique_ptr<World> World::assembleSuture(const SceneDesc& scene, std::vector<std::unique_ptr<TetMesh>> meshes,
                                             const std::vector<std::string>& active, const std::string& origin) {
    const suture::SutureSceneDesc& sd = *scene.suture;
    auto fail = [&](const std::string& rule) -> void { throw InputError(origin + ": scene: solver 'fem': " + rule); };
    if (!scene.surfaces.empty()) fail("surfaces (fascia) are not supported");
    if (!scene.tools.empty()) fail("haptic probes are not supported");
    if (scene.accuracy) fail("'accuracy' sampling is not supported");
    if (scene.xpbd.gravity.squaredNorm() > 0) fail("gravity is not used by the quasi-static FEM; remove it");
    if (!(scene.xpbd.dt > 0)) fail("dt must be positive");
    std::vector<int32_t> fixed;
    std::vector<int32_t> offsets;
    std::vector<const TetMesh*> parts;
    int32_t offset = 0;
    for (size_t i = 0; i < scene.bodies.size(); ++i) {
        const BodyDesc& b = scene.bodies[i];
        if (!b.embeddedIn.empty() || b.strainLimits || !b.nodeWeights.empty())
            fail("bodies[" + std::to_string(i) + "]: embedding, strain limits and node weights are not supported");
        if (b.material.youngsModulus != scene.bodies[0].material.youngsModulus ||
            b.material.poissonRatio != scene.bodies[0].material.poissonRatio)
            fail("bodies[" + std::to_string(i) + "].material: all bodies need the same youngs_modulus and poisson_ratio");
        for (int32_t v : b.fixedNodes) {
            if (v >= static_cast<int32_t>(meshes[i]->vertexCount()))
                fail("bodies[" + std::to_string(i) + "].fixed_nodes: node " + std::to_string(v) + " is out of range");
            fixed.push_back(v + offset);
        }
        offsets.push_back(offset);
        parts.push_back(meshes[i].get());
        offset += static_cast<int32_t>(meshes[i]->vertexCount());
    }
    std::vector<suture::NeedleFrame> trajectory = suture::parseTrajectory(sd.trajectoryText, origin + ": " + sd.trajectoryPath);
    suture::SutureSettings settings = sd.settings;
    settings.fem.youngsModulus = scene.bodies[0].material.youngsModulus;
    settings.fem.poissonRatio = scene.bodies[0].material.poissonRatio;
    // One core: a background refactorization would share it; results are then also repeatable.
    settings.fem.refactorMode = fem::RefactorMode::Synchronous;
    std::unique_ptr<World> w(new World());
    w->m_scene = scene;
    w->m_dt = scene.xpbd.dt;
    try {
        w->m_suture = suture::SutureSimulation::create(suture::mergeMeshes(parts, nullptr), fixed, settings,
                                                       trajectory.front().pose);
    } catch (const std::invalid_argument& e) {
        throw InputError(origin + ": scene cannot be simulated stably: " + e.what());
    }
    if (!sd.gauge[0].empty()) {
        for (int k = 0; k < 2; ++k) {
            size_t i = 0;
            while (i < scene.bodies.size() && scene.bodies[i].name != sd.gauge[k]) ++i;
            if (i == scene.bodies.size()) fail("suture.gauge: '" + sd.gauge[k] + "' is not a body of the scene");
            w->m_gaugeBodies[k] = i;
        }
        w->m_gaugeMesh = suture::mergeMeshes({parts[w->m_gaugeBodies[0]], parts[w->m_gaugeBodies[1]]}, nullptr);
        w->m_gaugeMesh->requireLevel(3);
        w->m_gauge = std::make_unique<suture::ClosureGauge>(
            *w->m_gaugeMesh, static_cast<int32_t>(parts[w->m_gaugeBodies[0]]->vertexCount()));
    }
    w->m_trajectory = std::move(trajectory);
    w->m_offsets = std::move(offsets);
    for (const auto& m : meshes) w->m_bodyX.push_back(m->positions());
    for (const BodyDesc& b : scene.bodies) w->m_names.push_back(b.name);
    w->m_meshes = std::move(meshes);
    if (w->m_gauge) w->m_initialGap = w->m_gauge->measure(w->gaugePositions()).maxGap;
    w->m_active = active;
    return w;
}

std::vector<Vec3> World::gaugePositions() const {
    std::vector<Vec3> x = m_bodyX[m_gaugeBodies[0]];
    x.insert(x.end(), m_bodyX[m_gaugeBodies[1]].begin(), m_bodyX[m_gaugeBodies[1]].end());
    return x;
}

FrameRecord World::stepSuture() {
    FrameRecord rec;
    rec.index = m_frame;
    suture::NeedleFrame frame = m_trajectory[std::min<size_t>(static_cast<size_t>(m_frame), m_trajectory.size() - 1)];
    if (!m_scene.suture->thread) frame.pull = 0;
    const auto t0 = std::chrono::steady_clock::now();
    const suture::SutureStepStats st = m_suture->step(frame);
    rec.stepMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    rec.substeps = 1;
    rec.iterations = st.solves;
    const auto& x = m_suture->positions();
    double maxMove = 0;
    bool finite = st.finite;
    for (size_t b = 0; b < m_bodyX.size(); ++b)
        for (size_t v = 0; v < m_bodyX[b].size(); ++v) {
            const Vec3& p = x[m_offsets[b] + v];
            finite = finite && p.allFinite();
            maxMove = std::max(maxMove, (p - m_bodyX[b][v]).norm());
            m_bodyX[b][v] = p;
        }
    rec.maxDisplacement = maxMove;
    rec.finite = finite;
    rec.energy = totalEnergy();
    SutureFrameRecord sr;
    sr.frame = m_frame;
    sr.activeRows = st.activeRows;
    sr.rejectedRows = st.rejectedRows;
    sr.contacts = st.contacts;
    sr.punctures = st.punctures;
    sr.threadTension = st.threadTension;
    sr.needleForce = st.needleForce;
    sr.threadEngaged = st.threadEngaged;
    if (m_gauge && m_frame % 10 == 0) { // sampled, outside the timed step
        const suture::ClosureMetrics cm = m_gauge->measure(gaugePositions());
        sr.maxGap = cm.maxGap;
        sr.maxPenetration = cm.maxPenetration;
        m_sampledPenetration = std::max(m_sampledPenetration, cm.maxPenetration);
        finite = finite && cm.finite;
    }
    m_sutureFrames.push_back(sr);
    m_invariants.record(finite && std::isfinite(rec.energy) && std::isfinite(st.threadTension), rec.energy, maxMove, 0.0);
    ++m_frame;
    m_time += m_dt;
    return rec;
}

SutureSummary World::sutureSummary() const {
    SutureSummary s;
    if (!m_suture) return s;
    for (const SutureFrameRecord& r : m_sutureFrames) {
        s.punctures = std::max(s.punctures, r.punctures);
        s.maxThreadTension = std::max(s.maxThreadTension, r.threadTension);
        s.maxActiveRows = std::max(s.maxActiveRows, r.activeRows);
        s.maxContacts = std::max(s.maxContacts, r.contacts);
    }
    if (!m_sutureFrames.empty()) s.finalThreadTension = m_sutureFrames.back().threadTension;
    if (m_gauge) {
        const suture::ClosureMetrics cm = m_gauge->measure(gaugePositions());
        s.gauge = true;
        s.initialGap = m_initialGap;
        s.finalGap = cm.maxGap;
        s.maxPenetration = std::max(m_sampledPenetration, cm.maxPenetration);
        s.finite = cm.finite;
    }
    s.finite = s.finite && m_invariants.allFinite;
    return s;
}

} // namespace viscera::sim
