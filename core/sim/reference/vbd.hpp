#pragma once
/// Vertex Block Descent (Chen, Macklin et al., "Vertex Block Descent", SIGGRAPH 2024) on one
/// implicit step (StepProblem), a candidate for the rectum's cost against XPBD measured by
/// bench_accuracy --variants: Gauss–Seidel over the free nodes in index order; node i moves by
/// -H_i⁻¹ g_i with g_i = m_i (x_i − x̃_i) + Σ_e ∂(h² V_e w_e Ψ_e)/∂x_i over its tets and
/// H_i = m_i I + Π⁺(Σ_e ∂²(h² V_e w_e Ψ_e)/∂x_i²) (3 × 3 blocks by central differences of the
/// analytic gradient, negative eigenvalues clamped to 0). It minimizes f itself, so its iterates
/// approach Newton's x*, at any step h. A measuring implementation (serial, finite-difference
/// blocks: 7 stress evaluations per tet and node), not a production kernel.
#include "sim/reference/accuracy.hpp"
#include "sim/xpbd/step_problem.hpp"

#include <functional>
#include <vector>

namespace viscera::sim {

using VbdObserver = std::function<void(int k, const std::vector<Vec3>& xk, double seconds)>;

/// Runs `iterations` sweeps from x_0 = x̃, calling observe(k, x_k, seconds) after sweep k
/// (seconds: the sweeps' cumulative wall time). fdStep: central-difference step relative to the
/// tet's size ∛(6 V). Throws std::invalid_argument when iterations < 1 or the problem is
/// inconsistent (sizes, node indices).
void iterateVbd(const StepProblem& problem, int iterations, const VbdObserver& observe, double fdStep = 1e-5);

/// iterateVbd's iterates against the Newton reference of the same problem (trace "vbd").
AccuracyTrace measureVbd(const StepProblem& problem, int iterations, const NewtonSettings& settings = {});

} // namespace viscera::sim
