#pragma once
/// The simulated world, assembled from a case's scene and feature list: only the subsystems the
/// case declares and uses are created (a case without "gravity" computes no gravity, one without
/// surfaces builds no fascia layer, one without "accuracy" runs no reference solves).
#include "sim/diagnostics/invariants.hpp"
#include "sim/scene/interaction_runtime.hpp"
#include "sim/scene/scene.hpp"
#include "sim/scene/tool_probe.hpp"
#include "sim/suture/anastomosis.hpp"
#include "sim/xpbd/xpbd_solver.hpp"
#include "sim/xpbd/xpbd_system.hpp"

#include <memory>
#include <string>
#include <vector>

namespace viscera::sim {

/// Feature names of case manifests understood by this build, sorted.
const std::vector<std::string>& supportedFeatures();
/// The features a scene needs (what an exporter writes into the manifest), sorted.
std::vector<std::string> requiredFeatures(const SceneDesc& scene);

struct FrameRecord {
    int index = 0;
    double stepMs = 0;          ///< wall time of the physics step, ms
    int substeps = 0;
    int iterations = 0;
    double energy = 0;          ///< J, elastic + kinetic + gravitational
    double maxDisplacement = 0; ///< m, largest node displacement in this frame
    bool finite = true;
};

/// One sampled frame of "error against run time" [A eq. 4.45].
struct AccuracyRecord {
    int frame = 0;
    std::string solver;              ///< "xpbd" or "newton"
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
    double maxGap = -1;       ///< m, closure gauge on sampled frames (every 10th), else −1
    double maxPenetration = -1; ///< m, same sampling
};

struct SutureSummary {
    int punctures = 0;
    double finalThreadTension = 0, maxThreadTension = 0; ///< N
    int maxActiveRows = 0, maxContacts = 0;
    bool gauge = false;            ///< the scene names two bodies to gauge
    double initialGap = 0;         ///< m
    double finalGap = 0;           ///< m, measured on the current state
    double maxPenetration = 0;     ///< m, over the sampled frames and the current state
    bool finite = true;
};

class World {
public:
    /// meshes[i] belongs to scene.bodies[i], surfaces[s] to scene.surfaces[s]. Throws
    /// viscera::InputError naming `origin`, the field and the rule: unsupported feature, a feature
    /// the scene needs but the manifest does not declare, a body or layer that cannot be simulated
    /// stably (bad material or curves, fixed node out of range, inverted rest element, embedded
    /// node outside its cage, nothing free to move).
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
    double time() const { return m_time; }
    int frameCount() const { return m_frame; }
    size_t bodyCount() const { return m_meshes.size(); }
    const std::string& bodyName(size_t i) const { return m_names[i]; }
    const TetMesh& restMesh(size_t i) const { return *m_meshes[i]; }
    const std::vector<Vec3>& positions(size_t i) const;
    size_t surfaceCount() const { return m_surfaces.size(); }
    const std::vector<Vec3>& surfacePositions(size_t s) const;
    /// Surface s as assembled (rest positions, triangles) and its scene name (renderer input).
    const TriMesh& surfaceMesh(size_t s) const { return m_surfaces[s]; }
    const std::string& surfaceName(size_t s) const { return m_scene.surfaces[s].name; }
    double totalEnergy() const;

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
    const InteractionRuntime* interaction() const { return m_interaction.get(); }

    // ---- suturing (solver "fem"; features fem, needle, thread, contact) ---------------------------
    /// Only a "fem" scene creates the suturing simulation; the needle follows the case's recorded
    /// trajectory, one frame per step (the last frame is held after the end).
    bool hasSuture() const { return m_suture != nullptr; }
    const std::vector<SutureFrameRecord>& sutureFrames() const { return m_sutureFrames; }
    /// Figures so far; the closure gauge is evaluated on the current state (O(facing × tets)).
    SutureSummary sutureSummary() const;

private:
    World() = default;
    void measureAccuracy();
    void applyTools(bool measure);
    static std::unique_ptr<World> assembleSuture(const SceneDesc& scene, std::vector<std::unique_ptr<TetMesh>> meshes,
                                                 const std::vector<std::string>& active, const std::string& origin);
    FrameRecord stepSuture();
    std::vector<Vec3> gaugePositions() const;

    SceneDesc m_scene;
    std::vector<std::string> m_active;
    std::vector<std::string> m_names;
    std::vector<std::unique_ptr<TetMesh>> m_meshes;
    std::vector<TriMesh> m_surfaces;
    std::unique_ptr<XpbdSolver> m_single;  ///< one tet body, no layers (accuracy hooks available)
    std::unique_ptr<XpbdSystem> m_system;  ///< several bodies and layers
    std::unique_ptr<ToolProbes> m_probes;  ///< null unless the scene has tools
    std::unique_ptr<InteractionRuntime> m_interaction; ///< null unless the scene has "interaction"
    std::unique_ptr<suture::SutureSimulation> m_suture; ///< null unless solver "fem"
    std::vector<suture::NeedleFrame> m_trajectory;
    std::vector<int32_t> m_offsets;                     ///< first merged node of each body
    std::vector<std::vector<Vec3>> m_bodyX;             ///< per-body positions (fem)
    std::unique_ptr<TetMesh> m_gaugeMesh;               ///< the two gauged bodies, merged
    std::unique_ptr<suture::ClosureGauge> m_gauge;
    std::array<size_t, 2> m_gaugeBodies{};
    std::vector<SutureFrameRecord> m_sutureFrames;
    double m_initialGap = 0, m_sampledPenetration = 0;
    Invariants m_invariants;
    std::vector<AccuracyRecord> m_accuracy;
    double m_time = 0;
    double m_dt = 0;
    int m_frame = 0;
};

} // namespace viscera::sim
