#pragma once
/// Kinematic sphere tools (probes) driven by a haptic device, and their contact with the tissue.
///
/// Each frame the World (1) moves every probe to the position the servo loop last published,
/// (2) pushes the nodes inside a probe out to its surface (inward relative velocity removed),
/// (3) steps the solver, (4) measures how far the tissue came back into each probe and turns
/// that penetration into a contact force, then pushes the nodes out again. The force follows
/// Hertz contact of a sphere of radius R on an elastic half-space with the body's modulus
/// E* = E / (1 − ν²): F = 4/3 E* √R d^{3/2} for a penetration d, local stiffness
/// dF/dd = 2 E* √(R d) (a case may set a linear stiffness instead). Fixed nodes and embedded
/// bodies are not pushed; surface layers (fascia) do not collide with probes in this version.
/// Contact is node-based: a probe smaller than the node spacing can slip between surface nodes.
/// Cost per frame O(#tools × #nodes).
#include "sim/mesh/tet_mesh.hpp"
#include "sim/scene/port.hpp"

#include <optional>
#include <string>
#include <vector>

namespace viscera::sim {

/// scene.json "tools": [{"name": "probe", "shape": "sphere", "radius": 0.005, "hand": "right",
///   "start": [0.06, 0.02, 0.04], "motion_scale": 0.25, "force_scale": 1.0, "stiffness": 0,
///   "max_force_n": 15, "damage_force_n": 4, "port": {...}}]      port: sim/scene/port.hpp
struct ToolDesc {
    std::string name;
    std::string hand = "any";  ///< "left", "right" or "any": which master drives it
    double radius = 0.005;     ///< m
    Vec3 start = Vec3::Zero(); ///< m, scene: centre when the master is at its workspace centre
    double motionScale = 0.25; ///< scene metres per device metre
    double forceScale = 1.0;   ///< device newtons per scene newton
    double stiffness = 0;      ///< N/m linear contact stiffness; 0 = Hertz from the body's material
    double maxForceN = 15.0;   ///< N, the case's maximum device force
    /// N, contact force above which tissue is damaged (session metrics); none: the case's
    /// assessment force_threshold_n.
    std::optional<double> damageForceN;
    PortDesc port; ///< "port" (port.hpp): the probe's shaft passes through it
};

/// One probe's contact after the last frame.
struct ToolContact {
    Vec3 centre = Vec3::Zero();  ///< m, where the probe was during the step
    Vec3 force = Vec3::Zero();   ///< N, on the probe (from the tissue)
    Vec3 normal = Vec3::UnitZ(); ///< unit: from the tissue towards the probe
    double penetration = 0;      ///< m, deepest node inside the probe after the step
    double gap = 1e9;            ///< m, distance to the nearest node when not in contact
    double stiffness = 0;        ///< N/m, local dF/dd
    int nodes = 0;               ///< nodes in contact
};

/// The per-frame probe work on plain arrays (World owns the solver and hands it the states).
class ToolProbes {
public:
    struct Body {
        std::vector<double> mass; ///< kg per node (0: do not push, e.g. fixed)
        double modulus = 0;       ///< Pa, E / (1 − ν²)
    };
    ToolProbes(std::vector<ToolDesc> tools, std::vector<Body> bodies, double dt);
    size_t size() const { return m_tools.size(); }
    const ToolDesc& desc(size_t t) const { return m_tools[t]; }
    const ToolContact& contact(size_t t) const { return m_contacts[t]; }
    /// Non-finite positions are ignored; a move longer than the radius is cut to the radius per
    /// frame (no tunnelling through thin tissue); with a port, the centre is then held to the
    /// port's limits (constrainToPort).
    void setPosition(size_t t, const Vec3& centre);
    const Vec3& position(size_t t) const { return m_pos[t]; }
    /// x[b], v[b]: positions and velocities of body b (in/out). Returns, per body, whether it
    /// changed. `measure`: after the step (records contacts) rather than before.
    std::vector<char> apply(std::vector<std::vector<Vec3>>& x, std::vector<std::vector<Vec3>>& v, bool measure);

private:
    std::vector<ToolDesc> m_tools;
    std::vector<Body> m_bodies;
    std::vector<ToolContact> m_contacts;
    std::vector<Vec3> m_pos, m_stepStart;
    std::vector<PortFrame> m_portFrames; ///< per tool, made once (its port, where declared)
    double m_dt;
};

/// Lumped node masses (ρ V / 4 per tet node), fixed nodes at 0.
std::vector<double> lumpedMasses(const TetMesh& mesh, double density, const std::vector<int32_t>& fixedNodes);

} // namespace viscera::sim
