#pragma once
/// The solver interface a World runs its bodies through. A World holds one SceneSolver and
/// forwards to it; it never asks which back-end it holds. Implementations:
///   - XpbdSceneSolver (xpbd_scene_solver.hpp): solver "xpbd", one XpbdSystem for every body,
///     surface and coupling, the scripted instruments, accuracy sampling on one-body scenes;
///   - FemSceneSolver (fem_scene_solver.hpp): solver "fem", the suturing simulation (quasi-static
///     corotational FEM, needle on the case's trajectory, thread, contact, closure gauge).
/// makeSceneSolver() picks one from the scene's solver type.
#include "sim/mesh/tet_mesh.hpp"
#include "sim/mesh/tri_mesh.hpp"
#include "sim/scene/scene.hpp"
#include "sim/xpbd/xpbd_settings.hpp"

#include <atomic>
#include <memory>
#include <string>
#include <vector>

namespace viscera::sim {

class InteractionRuntime;

/// One sampled frame of "error against run time" [A eq. 4.45].
struct AccuracyRecord {
    int frame = 0;
    std::string solver; ///< "xpbd" or "newton"
    std::vector<int> iterations;
    std::vector<double> relError;
    std::vector<double> timeMs;
};

/// One frame of the suturing FEM (solver "fem").
struct SutureFrameRecord {
    int frame = 0;
    int activeRows = 0;       ///< constraint rows enforced
    int rejectedRows = 0;     ///< redundant or incompatible rows rejected
    int contacts = 0;         ///< contact constraints held
    int punctures = 0;        ///< boundary punctures so far
    double threadTension = 0; ///< N, from the pull multipliers
    double needleForce = 0;   ///< N, resultant of the tissue on the needle
    bool threadEngaged = false;
    double maxGap = -1;         ///< m, closure gauge on sampled frames (every 10th), else −1
    double maxPenetration = -1; ///< m, same sampling
};

struct SutureSummary {
    int punctures = 0;
    double finalThreadTension = 0, maxThreadTension = 0; ///< N
    int maxActiveRows = 0, maxContacts = 0;
    bool gauge = false;        ///< the scene names two bodies to gauge
    double initialGap = 0;     ///< m
    double finalGap = 0;       ///< m, measured on the current state
    double maxPenetration = 0; ///< m, over the sampled frames and the current state
    bool finite = true;        ///< the gauge's figures (the World adds its invariants)
};

/// Suturing figures of a solver that sutures (the session report's suture block).
class SutureReport {
public:
    /// One record per step so far.
    virtual const std::vector<SutureFrameRecord>& frames() const = 0;
    /// Figures so far; the closure gauge is evaluated on the current state (O(facing × tets)).
    virtual SutureSummary summary() const = 0;
    /// What the renderer draws: the needle's curve and length now, and the thread's path (the
    /// puncture points in thread order, then the needle's end).
    virtual NeedleCurve needleCurve() const = 0;
    virtual double needleLength() const = 0;
    virtual std::vector<Vec3> threadPath() const = 0;

protected:
    ~SutureReport() = default;
};

/// A suturing solver's needle as a device drives it (suture "device").
class NeedleDrive {
public:
    /// The first frame of the recorded trajectory: where the needle starts.
    virtual NeedleFrame restFrame() const = 0;
    /// From the next step on the needle takes `frame` instead of the recorded trajectory (a
    /// non-finite pose or pull is ignored by the step).
    virtual void drive(const NeedleFrame& frame) = 0;
    /// N: the tissue's force on the needle after the last step.
    virtual Vec3 needleForce() const = 0;
    /// N: the thread tension after the last step.
    virtual double threadTension() const = 0;

protected:
    ~NeedleDrive() = default;
};

/// Where a step stands in time.
struct FrameClock {
    int frame = 0;   ///< index of the frame being stepped, from 0
    double time = 0; ///< s, at the frame's start
    double dt = 0;   ///< s, frame length
};

/// What a back-end is built from. The meshes and surfaces are owned by the World and outlive
/// the solver; meshes[i] belongs to scene.bodies[i], surfaces[s] to scene.surfaces[s].
struct SceneSolverInputs {
    const SceneDesc& scene;
    const std::vector<std::unique_ptr<TetMesh>>& meshes;
    const std::vector<TriMesh>& surfaces;
    const std::string& origin; ///< file named in messages
};

class SceneSolver {
public:
    virtual ~SceneSolver() = default;
    SceneSolver() = default;
    SceneSolver(const SceneSolver&) = delete;
    SceneSolver& operator=(const SceneSolver&) = delete;

    /// Advances every body by clock.dt (the part of World::step that is timed) and reports the
    /// frame's StepStats (sim/xpbd/xpbd_settings.hpp; the FEM gives one substep and its linear
    /// solves as iterations). Never throws.
    virtual StepStats step(const FrameClock& clock) = 0;
    /// After step(), untimed: the solver's own per-frame figures (FEM: the suture frame record and
    /// every 10th frame the closure gauge). False when one of them is not finite. Never throws.
    virtual bool recordFrame(const FrameClock& clock) = 0;
    /// On a sampled frame, before step(): appends the frame's AccuracyRecords [A eq. 4.45] (up to
    /// scene.accuracy's max_iterations), measured on a copy (the simulation is unchanged). A back-end without accuracy
    /// sampling rejects 'accuracy' at assembly and appends nothing. Never throws (a failed measurement is recorded as
    /// an empty trace).
    virtual void sampleAccuracy(const FrameClock& clock, std::vector<AccuracyRecord>& out) = 0;
    /// A flag (non-owning) that, once set, ends a sampleAccuracy() in progress within one Newton
    /// iteration and records nothing for it. Null: none.
    virtual void setAccuracyCancel(const std::atomic<bool>* flag) { (void)flag; }

    virtual const std::vector<Vec3>& positions(size_t body) const = 0;     ///< #V of the body, m
    virtual const std::vector<Vec3>& surfacePositions(size_t s) const = 0; ///< #V of surface s, m
    virtual double totalEnergy() const = 0; ///< J, what the back-end simulates (elastic, kinetic, gravity)

    // ---- dynamic state, for the haptic probes (back-ends without it reject probes at assembly) --
    virtual const std::vector<Vec3>& velocities(size_t body) const = 0; ///< #V, m/s
    /// Teleports a body between frames. Throws std::invalid_argument on a size mismatch or
    /// non-finite value.
    virtual void setState(size_t body, const std::vector<Vec3>& x, const std::vector<Vec3>& v) = 0;
    /// The same for surface s (fascia); back-ends without surfaces throw std::invalid_argument.
    virtual const std::vector<Vec3>& surfaceVelocities(size_t s) const = 0; ///< #V of surface s, m/s
    virtual void setSurfaceState(size_t s, const std::vector<Vec3>& x, const std::vector<Vec3>& v) = 0;

    /// Selective inertia scaling (solver.inertia_scaling): the extra inertia given to each body's
    /// nodes at assembly, kg per body (empty: a back-end without it).
    virtual std::vector<double> addedInertiaKg() const { return {}; }
    /// The scripted instruments (scene "interaction"), null when the scene has none.
    virtual const InteractionRuntime* interaction() const { return nullptr; }
    /// The same, to drive instruments between frames (a device).
    virtual InteractionRuntime* mutableInteraction() { return nullptr; }
    /// Suturing figures, null unless the back-end sutures.
    virtual const SutureReport* suture() const { return nullptr; }
    /// The needle of a suturing solver, to drive it from a device; null otherwise.
    virtual NeedleDrive* needleDrive() { return nullptr; }
    virtual const NeedleDrive* needleDrive() const { return nullptr; }
};

/// The back-end of scene.solverType ("fem": FemSceneSolver, otherwise XpbdSceneSolver). Throws
/// viscera::InputError naming in.origin, the field and the rule when the scene cannot be run.
std::unique_ptr<SceneSolver> makeSceneSolver(const SceneSolverInputs& in);

} // namespace viscera::sim
