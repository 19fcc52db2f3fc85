#pragma once
/// XPBD soft-body solver for one tetrahedral body [A §4.4.2]: per-constraint compliance,
/// substeps × iterations, Lagrange multipliers accumulated over the iterations of a substep and
/// reset each substep [A eq. 4.43–4.44], velocity damping, speed clamp, rollback of a non-finite
/// frame.
///
/// Elasticity comes from any TetConstraintModel (1 or 2 constraints per tet; two are solved as
/// one 2×2 block, which keeps the rest state a fixed point) with per-tet stiffness weights w
/// (compliance α/w). The stable Neo-Hookean model runs a packed fast path (AVX2/FMA when the CPU
/// has it, four tets per instruction); other models go through TetConstraintModel::evaluate.
/// Optional anisotropic strain limits [A §4.3.4] are solved with the elastic constraints.
///
/// Constraints are greedy-coloured by shared nodes and each colour is split over
/// settings.threads threads; the Gauss–Seidel order is colour by colour, so results are
/// bit-identical from run to run and for every thread count (the AVX2 and the scalar kernel
/// differ from each other in the last bits). For several bodies and coupled layers see
/// XpbdSystem, which this class wraps.
///
/// Limits of the method (measured, see tests/sim/xpbd):
///   - Stability: the stable Neo-Hookean split carries a rest pretension (C_D = √3 at F = I)
///     whose geometric stiffness XPBD ignores; with multipliers restarted every substep it is
///     stable only while the stiffness number h² k w / (ρ L²) stays below about 2 (energy gain
///     measured by bench/bench_stability_margin: first above bound between 1.3 and 2.4 on a small
///     cantilever at ν = 0.49, between 2.8 and 44 on the samples' bodies;
///     sim/diagnostics/stability_check.hpp refuses bodies above 1). More iterations do not
///     help, more substeps do. Constraints that vanish at rest (a one-constraint
///     EnergyConstraintModel, strain limits, membranes, ties) have no such limit: far beyond it
///     they behave like PBD, as stiff as the iterations make them.
///   - Equilibrium: XPBD drops the primal residual M(x − x̃) − ∇Cᵀλ, so its fixed point is off
///     the static equilibrium by O(h² k/m) whatever the iteration count (a 3 cm block at
///     20 kPa, 1 cm elements, 20 substeps of 1/60 s: 8e-5 m). It vanishes as h² / ρ.
///     XpbdSettings::primalCorrection removes it: each iteration is followed by
///     x ← x̃ + M⁻¹∇C(x)ᵀλ, and the iterations of a substep converge to the implicit step's
///     solution (bench/bench_accuracy: 1.4e-6 relative error after 5 iterations on a 4,944-tet
///     organ at 20 substeps, where plain XPBD levels off at 1.4e-2).
#include "sim/material/material.hpp"
#include "sim/mesh/tet_mesh.hpp"
#include "sim/xpbd/step_problem.hpp"
#include "sim/xpbd/xpbd_settings.hpp"
#include "sim/xpbd/xpbd_system.hpp"

#include <functional>
#include <memory>
#include <vector>

namespace viscera::sim {

/// How iterateOn() iterates.
enum class XpbdIteration {
    /// XPBD as step() runs it [A eq. 4.43–4.44]: the primal residual g(x, λ) of [A eq. 4.41] is
    /// dropped, so the iterates level off at a fixed point off x* by O(h² k / m).
    Standard,
    /// Each sweep is followed by the primal correction x ← x̃ + M⁻¹ ∇C(x)ᵀ λ (g = 0 at the
    /// current gradients), which the sweep's local updates keep only to first order. Its fixed
    /// point satisfies both rows of [A eq. 4.41], so the iterates converge to x* itself. Costs
    /// one gradient evaluation per tet per iteration (serial) on top of the sweep.
    PrimalCorrected,
    /// Chebyshev semi-iterative acceleration of the sweeps (Wang 2015, "A Chebyshev semi-iterative
    /// approach for accelerating projective and position-based dynamics"): after sweep k >= 2,
    /// x_k <- w_k (x_k - x_{k-2}) + x_{k-2}, w_2 = 2 / (2 - rho^2), w_k = 4 / (4 - rho^2 w_{k-1}),
    /// rho the spectral radius estimated from the plain sweeps; the multipliers are left as the
    /// sweeps made them. One pass over the positions per sweep; with one sweep per substep (the
    /// production setting) it changes nothing. Measured by bench_accuracy --variants only.
    Chebyshev,
};

class XpbdSolver {
public:
    /// body.mesh is read during create only. Throws viscera::PreconditionError (a
    /// std::invalid_argument whose rule has no function prefix, sim/util/error.hpp)
    /// ("sim::XpbdSolver::create(): fixed node 12 is out of range (mesh has 10 vertices)") on
    /// invalid settings, a null mesh or model, a model with other than 1 or 2 constraints, bad
    /// density, node weights or strain limits, a fixed node out of range, a tet with non-positive
    /// rest volume, or a body with no free node.
    static std::unique_ptr<XpbdSolver> create(const TetBodyDesc& body, const XpbdSettings& settings);
    /// Convenience: a StableNeoHookeanModel from the material's Lamé parameters, its density, all
    /// weights 1, no strain limits. Also throws on an invalid material.
    static std::unique_ptr<XpbdSolver> create(const TetMesh& rest, const Material& material,
                                              const std::vector<int32_t>& fixedNodes, const XpbdSettings& settings);
    ~XpbdSolver();
    XpbdSolver(const XpbdSolver&) = delete;
    XpbdSolver& operator=(const XpbdSolver&) = delete;

    /// Advances one frame (settings().dt). Never throws; a non-finite result is rolled back.
    StepStats step();

    const std::vector<Vec3>& positions() const;  ///< #V, metres
    const std::vector<Vec3>& velocities() const; ///< #V, m/s
    const XpbdSettings& settings() const;
    size_t tetCount() const { return m_template.tets.size(); }
    const TetConstraintModel& model() const { return *m_template.model; }
    const std::vector<double>& tetWeights() const { return m_template.weight; } ///< #T
    int colourCount() const;
    bool usesSimd() const;

    /// Teleports the body (x, v: #V each, finite); fixed nodes are then held at the new x.
    /// Between frames only. Throws viscera::PreconditionError (a std::invalid_argument,
    /// sim/util/error.hpp) on a size mismatch or non-finite value.
    void setState(const std::vector<Vec3>& x, const std::vector<Vec3>& v);

    /// Installs (empty function: removes) a hook called after every sweep of every substep of
    /// step(), with the particles (this body's nodes, index = node) at the current iterate, and
    /// once per substep after its velocity update; see XpbdIterationHook. Tool contacts: sim::makeCollisionHook
    /// (collision_solver.hpp). Between frames only. Without a hook step() is bit-identical to a solver that never had
    /// one.
    void setIterationHook(XpbdIterationHook hook);

    double elasticEnergy() const;   ///< J, relative to the rest state (plus violated compliant strain limits)
    double kineticEnergy() const;   ///< J
    double potentialEnergy() const; ///< J, gravity relative to the rest configuration
    double totalMass() const;       ///< kg

    // ---- measurement hooks for accuracy studies [A §4.4.3] --------------------------------------

    /// The implicit step that the next substep of step() iterates on, from the current state:
    /// h = dt / substeps, x̃ = x + h (v + h g) for free nodes (the prediction of step(), bit for
    /// bit), fixed nodes held at x; masses, tets, Dm⁻¹, volumes, weights and model of this body.
    /// Strain limits are not part of the problem. O(#V + #T).
    StepProblem nextSubstepProblem() const;

    using IterateObserver = std::function<void(int k, const std::vector<Vec3>& xk, double seconds)>;
    /// Runs `iterations` sweeps of the production XPBD iteration (the same blocks, colouring and
    /// kernels as step()) on the elastic constraints of `problem`, from x_0 = x̃ with multipliers 0,
    /// calling observe(k, x_k, seconds) after sweep k = 1..iterations; seconds is the cumulative
    /// wall time of the sweeps alone (each sweep is one job of the worker threads, so with
    /// threads > 1 it includes waking them, a few µs; the packing and colouring of the problem
    /// happen before the clock starts). On nextSubstepProblem() of a body without strain limits
    /// the iterates are those of step() bit for bit (with substeps = iterations = 1 and no speed
    /// clamp, x_1 is the position after the next step()). The
    /// solver's state is untouched; it shares the worker threads, so it must not run
    /// concurrently with step(). Throws std::invalid_argument on an inconsistent problem or
    /// iterations < 1.
    /// chebyshevRho: XpbdIteration::Chebyshev's rho in [0, 1).
    void iterateOn(const StepProblem& problem, int iterations, const IterateObserver& observe,
                   XpbdIteration mode = XpbdIteration::Standard, double chebyshevRho = 0.0) const;

    /// The one-body system this solver wraps (its tet body 0 is this body): stepping or setting
    /// state through it is stepping or setting state here (XpbdSystem::setTetState(0, ...) is
    /// setState()). Non-owning; lives as long as this solver.
    XpbdSystem& system() { return *m_sys; }
    const XpbdSystem& system() const { return *m_sys; }

private:
    XpbdSolver();
    std::unique_ptr<XpbdSystem> m_sys;
    StepProblem m_template; ///< h and xTilde empty; the rest as in nextSubstepProblem()
};

} // namespace viscera::sim
