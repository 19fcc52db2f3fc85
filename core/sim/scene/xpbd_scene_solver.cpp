#include "sim/scene/xpbd_scene_solver.hpp"

#include "sim/diagnostics/stability_check.hpp"
#include "sim/reference/accuracy.hpp"
#include "sim/scene/features.hpp"
#include "sim/scene/interaction_runtime.hpp"
#include "sim/util/error.hpp"
#include "sim/util/format.hpp"

namespace viscera::sim {

XpbdSceneSolver::XpbdSceneSolver() = default;
XpbdSceneSolver::~XpbdSceneSolver() = default;

namespace {

/// The XpbdSystem description of the scene's bodies, surfaces and couplings (pointers into `in`).
/// Throws InputError on a material the model factory refuses.
XpbdSystemDesc describe(const SceneSolverInputs& in) {
    const SceneDesc& scene = in.scene;
    XpbdSystemDesc desc;
    for (size_t i = 0; i < scene.bodies.size(); ++i) {
        const BodyDesc& b = scene.bodies[i];
        TetBodyDesc tb;
        tb.name = b.name;
        tb.mesh = in.meshes[i].get();
        tb.model = makeConstraintModel(b.material, b.name); // InputError names material and curve
        tb.density = b.material.density;
        tb.fixedNodes = b.fixedNodes;
        tb.nodeWeights = b.nodeWeights;
        tb.strainLimits = b.strainLimits;
        desc.tetBodies.push_back(std::move(tb));
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
        sb.mesh = &in.surfaces[s];
        sb.arealDensity = sd.arealDensity;
        sb.stretchStiffness = sd.stretchStiffness;
        sb.nodeWeights = sd.nodeWeights;
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
    return desc;
}

/// XpbdSystem::create with its precondition failures as InputError naming the case file.
template <class Build> auto buildOrRefuse(const std::string& origin, const Build& build) {
    // The rule without the function prefix: the message names the case file instead.
    try {
        return build();
    } catch (const PreconditionError& e) {
        throw InputError(origin + ": scene cannot be simulated stably: " + e.rule);
    } catch (const std::invalid_argument& e) {
        throw InputError(origin + ": scene cannot be simulated stably: " + e.what());
    }
}

/// The inertia that hard ties of `system` (null: none) and selective inertia scaling add to the
/// nodes of tet body b, kg per node (empty: none).
std::vector<double> inertiaAddedTo(const XpbdSystem* system, size_t b) {
    if (!system) return {};
    std::vector<double> m = system->tiedInertia(b);
    const std::vector<double> extra = system->addedInertia(b);
    for (size_t i = 0; i < m.size(); ++i)
        m[i] += extra[i];
    return m;
}

/// The load-time rule per tet body, with the inertia that ties and scaling of `system` add.
std::vector<StabilityFigures> figuresOf(const SceneSolverInputs& in, const XpbdSystemDesc& desc,
                                        const XpbdSystem* system) {
    std::vector<StabilityFigures> out;
    for (size_t i = 0; i < desc.tetBodies.size(); ++i) {
        const TetBodyDesc& tb = desc.tetBodies[i];
        out.push_back(assessStability(*in.meshes[i], *tb.model, tb.density, tb.nodeWeights, in.scene.xpbd,
                                      inertiaAddedTo(system, i)));
    }
    return out;
}

/// The load-time rule, after selective inertia scaling (settings.inertiaScaling > 1) of the bodies
/// over the limit: their nodes get the extra inertia stabilizingInertia asks for (capped).
std::vector<StabilityFigures> scaleAndAssess(const SceneSolverInputs& in, const XpbdSystemDesc& desc,
                                             XpbdSystem& system) {
    std::vector<StabilityFigures> figures = figuresOf(in, desc, &system);
    const double scaling = in.scene.xpbd.inertiaScaling;
    if (!(scaling > 1)) return figures;
    bool scaled = false;
    for (size_t i = 0; i < figures.size(); ++i) {
        if (figures[i].ok()) continue;
        const TetBodyDesc& tb = desc.tetBodies[i];
        system.setAddedInertia(i, stabilizingInertia(*in.meshes[i], *tb.model, tb.density, tb.nodeWeights,
                                                     in.scene.xpbd, inertiaAddedTo(&system, i), scaling));
        scaled = true;
    }
    return scaled ? figuresOf(in, desc, &system) : figures;
}

} // namespace

std::vector<StabilityFigures> assessSceneStability(const SceneSolverInputs& in) {
    if (auto why = validate(in.scene.xpbd); !why.empty())
        throw InputError(in.origin + ": scene cannot be simulated stably: solver: " + why);
    const XpbdSystemDesc desc = describe(in);
    if (desc.embeddings.empty() && desc.attachments.empty() && !(in.scene.xpbd.inertiaScaling > 1))
        return figuresOf(in, desc, nullptr);
    const auto system = buildOrRefuse(in.origin, [&] { return XpbdSystem::create(desc, in.scene.xpbd); });
    return scaleAndAssess(in, desc, *system);
}

std::unique_ptr<XpbdSceneSolver> XpbdSceneSolver::create(const SceneSolverInputs& in) {
    const SceneDesc& scene = in.scene;
    const std::string& origin = in.origin;
    // One tet body without layers runs on the single-body solver, the one the Newton reference of
    // accuracy sampling mirrors.
    const bool layered = !supportsAccuracySampling(scene);
    if (scene.accuracy && layered)
        throw InputError(origin + ": features: 'accuracy' sampling needs a scene with a single tet body and no layers");

    if (auto why = validate(scene.xpbd); !why.empty())
        throw InputError(origin + ": scene cannot be simulated stably: solver: " + why);
    const XpbdSystemDesc desc = describe(in);
    std::unique_ptr<XpbdSceneSolver> x(new XpbdSceneSolver());
    buildOrRefuse(origin, [&] {
        if (layered) {
            x->m_layered = XpbdSystem::create(desc, scene.xpbd);
            x->m_sys = x->m_layered.get();
        } else {
            x->m_single = XpbdSolver::create(desc.tetBodies.front(), scene.xpbd);
            x->m_sys = &x->m_single->system();
        }
        return 0;
    });
    // Load-time stability rule, per body, with the inertia that hard ties add to its nodes (an
    // embedded body moves with its cage) and, when the scene allows it, selective inertia scaling
    // of the nodes of the tets over the limit.
    const std::vector<StabilityFigures> figures = scaleAndAssess(in, desc, *x->m_sys);
    for (size_t i = 0; i < figures.size(); ++i)
        if (auto why = stabilityProblem(scene.bodies[i].name, figures[i], scene.xpbd); !why.empty()) {
            if (scene.xpbd.inertiaScaling > 1)
                why += " (after inertia scaling up to " + formatNumber(scene.xpbd.inertiaScaling, 3) + "x)";
            throw InputError(origin + ": scene cannot be simulated stably: " + why);
        }
    for (size_t i = 0; i < figures.size(); ++i) {
        double kg = 0;
        for (double m : x->m_sys->addedInertia(i))
            kg += m;
        x->m_addedInertia.push_back(kg);
    }
    if (scene.interaction) {
        std::vector<const TetMesh*> bodies;
        for (const auto& m : in.meshes)
            bodies.push_back(m.get());
        std::vector<const TriMesh*> layers;
        for (const TriMesh& m : in.surfaces)
            layers.push_back(&m);
        x->m_interaction = InteractionRuntime::create(scene, *x->m_sys, bodies, layers, origin);
    }
    x->m_accuracy = scene.accuracy;
    x->m_primalCorrection = scene.xpbd.primalCorrection;
    return x;
}

StepStats XpbdSceneSolver::step(const FrameClock& clock) {
    if (m_interaction) m_interaction->beforeStep(clock.time + clock.dt, clock.dt);
    const StepStats st = m_sys->step();
    if (m_interaction) m_interaction->afterStep();
    return st;
}

void XpbdSceneSolver::sampleAccuracy(const FrameClock& clock, std::vector<AccuracyRecord>& out) {
    if (!m_single || !m_accuracy) return; // create() refuses 'accuracy' on layered scenes
    // Never throws from the per-frame path: a failed measurement is recorded as empty traces.
    auto keep = [&](AccuracyTrace t) {
        AccuracyRecord r;
        r.frame = clock.frame;
        r.solver = t.solver;
        r.iterations = std::move(t.iterations);
        r.relError = std::move(t.relError);
        r.timeMs = std::move(t.timeMs);
        out.push_back(std::move(r));
    };
    NewtonSettings reference;
    reference.cancel = m_accuracyCancel;
    auto cancelled = [&] { return m_accuracyCancel && m_accuracyCancel->load(std::memory_order_relaxed); };
    try {
        AccuracyTrace xpbd = measureXpbd(*m_single, m_accuracy->maxIterations, reference,
                                         m_primalCorrection ? XpbdIteration::PrimalCorrected : XpbdIteration::Standard);
        if (cancelled()) return; // measured against an unfinished reference: nothing to record
        AccuracyTrace newton = measureNewton(*m_single, reference);
        if (cancelled()) return;
        keep(std::move(xpbd));
        keep(std::move(newton));
    } catch (const std::exception&) {
        AccuracyRecord r;
        r.frame = clock.frame;
        r.solver = "xpbd";
        out.push_back(std::move(r));
    }
}

double XpbdSceneSolver::totalEnergy() const {
    return m_sys->elasticEnergy() + m_sys->kineticEnergy() + m_sys->potentialEnergy();
}

void XpbdSceneSolver::setState(size_t body, const std::vector<Vec3>& x, const std::vector<Vec3>& v) {
    m_sys->setTetState(body, x, v);
}

const std::vector<Vec3>& XpbdSceneSolver::surfaceVelocities(size_t s) const {
    return m_sys->surfaceVelocities(s);
}

void XpbdSceneSolver::setSurfaceState(size_t s, const std::vector<Vec3>& x, const std::vector<Vec3>& v) {
    m_sys->setSurfaceState(s, x, v);
}

} // namespace viscera::sim
