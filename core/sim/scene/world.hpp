#pragma once
/// The simulated world, assembled from a case's scene and feature list: only the subsystems the
/// case declares and uses are created (a case without "gravity" computes no gravity, one without
/// surfaces builds no fascia layer, one without "accuracy" runs no reference solves).
#include "sim/diagnostics/invariants.hpp"
#include "sim/scene/features.hpp"
#include "sim/scene/interaction_runtime.hpp"
#include "sim/scene/scene.hpp"
#include "sim/scene/scene_solver.hpp"
#include "sim/scene/tool_probe.hpp"

#include <memory>
#include <string>
#include <vector>

namespace viscera::sim {

struct FrameRecord {
    int index = 0;
    double stepMs = 0; ///< wall time of the physics step, ms
    int substeps = 0;
    int iterations = 0;
    double energy = 0;          ///< J, elastic + kinetic + gravitational
    double maxDisplacement = 0; ///< m, largest node displacement in this frame
    bool finite = true;
};

/// The bodies run through one SceneSolver (scene_solver.hpp: XPBD or the suturing FEM, chosen by
/// the scene's solver type); the World adds what is common to every back-end: feature checks,
/// haptic probes, invariants, accuracy sampling frames, time.
class World;

/// Refuses an XPBD scene whose frame would take more than XpbdLimits::maxConstraintSolvesPerFrame
/// constraint solves (substeps × iterations × tets and surface triangles): InputError
/// "<origin>: solver: substeps 1000 x iterations 1000 x 4608 elements = 4.61e+09 constraint solves
/// per frame, more than the work limit of 1e+08 ...". World::assemble checks it first; a loader
/// may check it earlier with the scene's own name as `origin`.
void checkWorkBudget(const SceneDesc& scene, const std::vector<std::unique_ptr<TetMesh>>& meshes,
                     const std::vector<TriMesh>& surfaces, const std::string& origin);

class World {
public:
    /// meshes[i] belongs to scene.bodies[i], surfaces[s] to scene.surfaces[s]. Throws
    /// viscera::InputError naming `origin`, the field and the rule: unsupported feature, a feature
    /// the scene needs but the manifest does not declare, a body or layer that cannot be simulated
    /// stably (bad material or curves, fixed node out of range, inverted rest element, embedded
    /// node outside its cage, nothing free to move), a frame over the work budget (checkWorkBudget).
    static std::unique_ptr<World> assemble(const SceneDesc& scene, std::vector<std::unique_ptr<TetMesh>> meshes,
                                           std::vector<TriMesh> surfaces, const std::vector<std::string>& features,
                                           const std::string& origin);
    World(const World&) = delete;
    World& operator=(const World&) = delete;
    ~World();

    /// One frame of every body; on sampled frames the accuracy of the frame's first substep is
    /// measured first (on a copy; the simulation itself is unchanged). Never throws.
    FrameRecord step();

    const std::vector<std::string>& activeSubsystems() const { return m_active; }
    const Invariants& invariants() const { return m_invariants; }
    const std::vector<AccuracyRecord>& accuracy() const { return m_accuracy; }
    /// Forgets the accuracy records so far (a long-running sampler keeps only what it reads).
    void clearAccuracy() { m_accuracy.clear(); }
    /// A flag (non-owning, outliving the world or reset to null) that ends a step's accuracy
    /// measurement in progress within one Newton iteration and records nothing for it: whoever
    /// stops a sampler does not wait for a converged reference.
    void setAccuracyCancel(const std::atomic<bool>* flag);
    double time() const { return m_time; }
    double dt() const { return m_dt; } ///< s, the frame time step of the scene's solver
    int frameCount() const { return m_frame; }
    size_t bodyCount() const { return m_meshes.size(); }
    const std::string& bodyName(size_t i) const { return m_names[i]; }
    const TetMesh& restMesh(size_t i) const { return *m_meshes[i]; }
    const std::vector<Vec3>& positions(size_t i) const { return m_solver->positions(i); }
    const std::vector<Vec3>& velocities(size_t i) const { return m_solver->velocities(i); } ///< m/s
    /// Replaces body i's positions and velocities (#V each; the studio's preview carries the
    /// motion over when it swaps in a world with an edited material). Throws
    /// std::invalid_argument on a size mismatch or a non-finite value.
    void setState(size_t i, const std::vector<Vec3>& x, const std::vector<Vec3>& v);
    const std::vector<Vec3>& surfaceVelocities(size_t s) const { return m_solver->surfaceVelocities(s); }
    void setSurfaceState(size_t s, const std::vector<Vec3>& x, const std::vector<Vec3>& v);
    size_t surfaceCount() const { return m_surfaces.size(); }
    const std::vector<Vec3>& surfacePositions(size_t s) const { return m_solver->surfacePositions(s); }
    /// Surface s as assembled (rest positions, triangles) and its scene name (renderer input).
    const TriMesh& surfaceMesh(size_t s) const { return m_surfaces[s]; }
    const std::string& surfaceName(size_t s) const { return m_scene.surfaces[s].name; }
    double totalEnergy() const { return m_solver->totalEnergy(); }
    /// Extra inertia selective inertia scaling gave each body's nodes at assembly, kg per body
    /// (empty when the back-end has none; SceneSolver::addedInertiaKg).
    std::vector<double> addedInertiaKg() const { return m_solver->addedInertiaKg(); }

    // ---- haptic probes (feature "probe": only scenes with tools create them) --------------------
    size_t toolCount() const { return m_probes ? m_probes->size() : 0; }
    const ToolDesc& toolDesc(size_t t) const { return m_probes->desc(t); }
    /// Where probe t is to be during the next step (m, scene). Between frames only; non-finite
    /// positions are ignored.
    void setToolPosition(size_t t, const Vec3& centre) { m_probes->setPosition(t, centre); }
    /// Contact of probe t measured by the last step (tool_probe.hpp).
    const ToolContact& toolContact(size_t t) const { return m_probes->contact(t); }

    // ---- scripted instruments (scene "interaction"; features collision, dissection, clip) --------
    /// Null unless the scene has an interaction section.
    const InteractionRuntime* interaction() const { return m_solver->interaction(); }
    /// The same, to drive instruments between frames (InteractionRuntime::drive).
    InteractionRuntime* interaction() { return m_solver->mutableInteraction(); }

    // ---- suturing (solver "fem"; features fem, needle, thread, contact) ---------------------------
    /// Only a "fem" scene creates the suturing simulation; the needle follows the case's recorded
    /// trajectory, one frame per step (the last frame is held after the end).
    bool hasSuture() const { return m_solver->suture() != nullptr; }
    /// The suturing figures and geometry (needle, thread) of a "fem" scene; null otherwise.
    const SutureReport* sutureReport() const { return m_solver->suture(); }
    /// The needle of a suturing scene, for a device to drive (suture "device"); null otherwise.
    NeedleDrive* needleDrive() { return m_solver->needleDrive(); }
    const NeedleDrive* needleDrive() const { return m_solver->needleDrive(); }
    // ---- the laparoscope (scene "laparoscope"): the camera on its port, steered between frames --
    /// Null unless the scene declares one. Kinematic: it changes nothing of the physics.
    const Laparoscope* laparoscope() const { return m_scope.get(); }
    Laparoscope* laparoscope() { return m_scope.get(); }
    /// The scene the world was assembled from.
    const SceneDesc& scene() const { return m_scene; }
    /// One record per step of a "fem" scene; empty otherwise.
    const std::vector<SutureFrameRecord>& sutureFrames() const;
    /// Figures so far; the closure gauge is evaluated on the current state (O(facing × tets)).
    SutureSummary sutureSummary() const;

private:
    World() = default;
    void applyTools(bool measure);

    SceneDesc m_scene;
    std::vector<std::string> m_active;
    std::vector<std::string> m_names;
    std::vector<std::unique_ptr<TetMesh>> m_meshes;
    std::vector<TriMesh> m_surfaces;
    std::unique_ptr<SceneSolver> m_solver; ///< after the meshes it reads from
    std::unique_ptr<ToolProbes> m_probes;  ///< null unless the scene has tools
    std::unique_ptr<Laparoscope> m_scope;  ///< null unless the scene has a laparoscope
    Invariants m_invariants;
    std::vector<AccuracyRecord> m_accuracy;
    double m_time = 0;
    double m_dt = 0;
    int m_frame = 0;
};

} // namespace viscera::sim
