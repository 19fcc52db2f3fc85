#pragma once
/// XPBD soft-body solver for one tetrahedral body [A §4.4.2]: per-constraint compliance,
/// substeps × iterations, Lagrange multipliers reset each substep, velocity damping.
///
/// Elasticity: the stable Neo-Hookean energy
///   Ψ = μ/2 (tr FᵀF − 3) + λ/2 (det F − γ)² − μ²/(2λ),   γ = 1 + μ/λ,
/// split into a deviatoric constraint C_D = sqrt(tr FᵀF) with compliance 1/(μ V) and a hydrostatic
/// constraint C_H = det F − γ with compliance 1/(λ V); both stay well defined under inversion.
/// The two constraints of a tet are solved as one 2×2 block, which keeps the rest state a fixed
/// point of the iteration.
/// Gauss–Seidel order is the tet order, so results are bit-identical from run to run.
#include "sim/material/material.hpp"
#include "sim/mesh/tet_mesh.hpp"

#include <Eigen/Core>

#include <memory>
#include <vector>

namespace viscera::sim {

struct XpbdSettings {
    double dt = 1.0 / 60.0;          ///< frame time step, s
    int substeps = 10;               ///< substeps per frame
    int iterations = 1;              ///< constraint sweeps per substep
    double damping = 1.0;            ///< velocity damping rate, 1/s
    Vec3 gravity = Vec3(0, 0, -9.81); ///< m/s^2, world frame
    double maxSpeed = 20.0;          ///< m/s; faster nodes are clamped (counted in StepStats)
};

/// Checks settings; empty string when valid, otherwise the rule that failed.
std::string validate(const XpbdSettings& s);

struct StepStats {
    bool finite = true;            ///< false: the step produced a non-finite value and was undone
    int substeps = 0;
    int iterations = 0;
    double maxDisplacement = 0;    ///< m, largest node displacement over the frame
    int speedClamps = 0;           ///< node-substeps whose speed was clamped to maxSpeed
};

class XpbdSolver {
public:
    /// Throws std::invalid_argument naming the rule: invalid material or settings, a fixed node out
    /// of range, a tet with non-positive rest volume, or a body with no free node.
    static std::unique_ptr<XpbdSolver> create(const TetMesh& rest, const Material& material,
                                              const std::vector<int32_t>& fixedNodes,
                                              const XpbdSettings& settings);
    XpbdSolver(const XpbdSolver&) = delete;
    XpbdSolver& operator=(const XpbdSolver&) = delete;

    /// Advances one frame (settings().dt). Never throws; a non-finite result is rolled back.
    StepStats step();

    const std::vector<Vec3>& positions() const { return m_x; }  ///< #V, metres
    const std::vector<Vec3>& velocities() const { return m_v; } ///< #V, m/s
    const XpbdSettings& settings() const { return m_settings; }
    size_t tetCount() const { return m_tets.size(); }

    double elasticEnergy() const;   ///< J
    double kineticEnergy() const;   ///< J
    double potentialEnergy() const; ///< J, gravity relative to the rest configuration
    double totalMass() const;       ///< kg

private:
    XpbdSolver() = default;
    void solveTet(size_t t, double h2inv);

    XpbdSettings m_settings;
    std::vector<Tet> m_tets;
    std::vector<Eigen::Matrix3d> m_dmInv; // inverse rest shape matrices
    std::vector<double> m_restVolume;
    std::vector<double> m_invMass;        // 0 for fixed nodes
    std::vector<double> m_mass;
    std::vector<Vec3> m_rest, m_x, m_v, m_prev, m_frameStart;
    std::vector<double> m_multipliers; // 2 per tet (deviatoric, hydrostatic), reset each substep
    double m_mu = 0, m_lambda = 0, m_gamma = 1;
};

} // namespace viscera::sim
