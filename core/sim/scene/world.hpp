#pragma once
/// The simulated world, assembled from a case's scene and feature list: only the subsystems the
/// case declares and uses are created (a case without "gravity" computes no gravity, one without
/// surfaces builds no fascia layer, one without "accuracy" runs no reference solves).
#include "sim/diagnostics/invariants.hpp"
#include "sim/scene/scene.hpp"
#include "sim/scene/tool_probe.hpp"
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

private:
    World() = default;
    void measureAccuracy();
    void applyTools(bool measure);

    SceneDesc m_scene;
    std::vector<std::string> m_active;
    std::vector<std::string> m_names;
    std::vector<std::unique_ptr<TetMesh>> m_meshes;
    std::vector<TriMesh> m_surfaces;
    std::unique_ptr<XpbdSolver> m_single;  ///< one tet body, no layers (accuracy hooks available)
    std::unique_ptr<XpbdSystem> m_system;  ///< several bodies and layers
    std::unique_ptr<ToolProbes> m_probes;  ///< null unless the scene has tools
    Invariants m_invariants;
    std::vector<AccuracyRecord> m_accuracy;
    double m_time = 0;
    double m_dt = 0;
    int m_frame = 0;
};

} // namespace viscera::sim
