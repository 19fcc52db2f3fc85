#pragma once
/// The simulated world, assembled from a case's scene and feature list: only the subsystems the
/// case declares are created (a case without "gravity" computes no gravity, and so on).
#include "sim/diagnostics/invariants.hpp"
#include "sim/scene/scene.hpp"
#include "sim/xpbd/xpbd_solver.hpp"

#include <memory>
#include <string>
#include <vector>

namespace viscera::sim {

/// Feature names of case manifests understood by this build, sorted.
const std::vector<std::string>& supportedFeatures();

struct FrameRecord {
    int index = 0;
    double stepMs = 0;          ///< wall time of the physics step, ms
    int substeps = 0;
    int iterations = 0;
    double energy = 0;          ///< J, elastic + kinetic + gravitational
    double maxDisplacement = 0; ///< m, largest node displacement in this frame
    bool finite = true;
};

class World {
public:
    /// meshes[i] belongs to scene.bodies[i]. Throws viscera::InputError naming `origin`, the
    /// field and the rule: unsupported feature, a feature the scene needs but the manifest does not
    /// declare, a body that cannot be simulated stably (bad material, fixed node out of range,
    /// inverted rest element, no free node).
    static std::unique_ptr<World> assemble(const SceneDesc& scene,
                                           std::vector<std::unique_ptr<TetMesh>> meshes,
                                           const std::vector<std::string>& features,
                                           const std::string& origin);
    World(const World&) = delete;
    World& operator=(const World&) = delete;

    /// One frame of every body. Never throws.
    FrameRecord step();

    const std::vector<std::string>& activeSubsystems() const { return m_active; }
    const Invariants& invariants() const { return m_invariants; }
    double time() const { return m_time; }
    int frameCount() const { return m_frame; }
    size_t bodyCount() const { return m_bodies.size(); }
    const std::string& bodyName(size_t i) const { return m_names[i]; }
    const XpbdSolver& body(size_t i) const { return *m_bodies[i]; }
    const TetMesh& restMesh(size_t i) const { return *m_meshes[i]; }
    double totalEnergy() const;

private:
    World() = default;
    std::vector<std::string> m_active;
    std::vector<std::string> m_names;
    std::vector<std::unique_ptr<TetMesh>> m_meshes;
    std::vector<std::unique_ptr<XpbdSolver>> m_bodies;
    Invariants m_invariants;
    double m_time = 0;
    double m_dt = 0;
    int m_frame = 0;
};

} // namespace viscera::sim
