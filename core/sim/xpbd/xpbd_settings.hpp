#pragma once
/// Settings and per-frame statistics shared by the XPBD solvers [A §4.4.2].
#include "sim/mesh/tri_mesh.hpp"

#include <string>

namespace viscera::sim {

/// Default worker count: std::thread::hardware_concurrency() clamped to [2, 8] (2 when unknown).
int defaultXpbdThreads();

struct XpbdSettings {
    double dt = 1.0 / 60.0;           ///< frame time step, s
    int substeps = 10;                ///< substeps per frame
    int iterations = 1;               ///< constraint sweeps per substep
    double damping = 1.0;             ///< velocity damping rate, 1/s
    Vec3 gravity = Vec3(0, 0, -9.81); ///< m/s^2, world frame
    double maxSpeed = 20.0;           ///< m/s; faster nodes are clamped (counted in StepStats)
    /// Threads that share the constraint sweeps (1 = serial, on the calling thread). Constraints
    /// are graph-coloured, so results are bit-identical for every thread count.
    int threads = defaultXpbdThreads();
    /// Use the AVX2/FMA stable Neo-Hookean kernel when the CPU has it. false forces the portable
    /// scalar kernel (same equations; results differ from the SIMD kernel in the last bits).
    bool simd = true;
    /// After every iteration, the primal correction x ← x̃ + M⁻¹ ∇C(x)ᵀ λ (XpbdIteration::
    /// PrimalCorrected): iterations then converge to the implicit step's solution instead of
    /// levelling off O(h² k/m) away from it, at about 4 times the cost of a plain iteration
    /// (parallel like the sweeps, bit-identical for any thread count). Elastic tets only (no strain limits, membranes or ties); converges while the
    /// stiffness number h² k w/(ρ L²) is small, which the load-time stability check enforces.
    bool primalCorrection = false;
};

/// Checks settings; empty string when valid, otherwise the rule that failed.
std::string validate(const XpbdSettings& s);

struct StepStats {
    bool finite = true; ///< false: the step produced a non-finite value and was undone
    int substeps = 0;
    int iterations = 0;
    double maxDisplacement = 0; ///< m, largest node displacement over the frame
    int speedClamps = 0;        ///< node-substeps whose speed was clamped to maxSpeed
};

} // namespace viscera::sim
