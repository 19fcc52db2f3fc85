#pragma once
/// Newton reference solver for one implicit-Euler step (StepProblem): the converged x* against
/// which the relative error (f(x_k) − f(x*)) / (f(x_0) − f(x*)) of every other solver is measured
/// [A §4.4.3, eq. 4.45]. A measuring tool, not a production solver: it is exact and slow.
///
/// Method, per iteration k:
///   - H = M + Σ_e Π⁺(H_e), with H_e (12 × 12) the Hessian of the tet's term h² V_e w_e Ψ_e(F_e)
///     by central finite differences of its analytic gradient, symmetrized, and Π⁺ the projection
///     to positive semi-definite (eigen-decomposition, negative eigenvalues clamped to 0);
///     fixed nodes (and nodes with neither mass nor tets) are eliminated as identity rows.
///     The projection guarantees a descent direction but, where element Hessians are indefinite
///     at x* (stable Neo-Hookean under load), makes the final convergence linear (measured: about
///     ×30 per iteration instead of quadratic); NewtonHessian::ExactWhenDefinite restores the
///     quadratic tail;
///   - sparse Cholesky LLᵀ (CHOLMOD, supernodal): the pattern is analysed once per solve and only
///     refactorized numerically each iteration; solve H d = −∇f;
///   - backtracking Armijo line search on f.
/// Stops when ‖∇f‖∞ ≤ tolerance · max(1, ‖∇f(x_0)‖∞) and ‖∇f‖∞ ≤ relativeTolerance · ‖∇f(x_0)‖∞
/// (Converged); when the line search finds no acceptable step or the step falls below
/// floating-point resolution (Converged if the first test holds — the gradient is then at its
/// rounding floor, noted in the message — otherwise Stalled); or after maxIterations
/// (MaxIterations). Numerical failures (a factorization that is not positive
/// definite, a non-finite value) end the solve with a status and a message, never an exception.
///
/// Cost per iteration: 24 stress evaluations and one 12 × 12 eigen-decomposition per tet, one
/// numerical sparse factorization of a 3#V × 3#V matrix. The library never prints.
#include "sim/xpbd/step_problem.hpp"

#include <array>
#include <atomic>
#include <string>
#include <vector>

namespace viscera::sim {

enum class NewtonHessian {
    Projected, ///< M + Σ Π⁺(H_e) every iteration
    /// M + Σ H_e when CHOLMOD finds it positive definite, else M + Σ Π⁺(H_e) (one more numeric
    /// factorization in that case).
    ExactWhenDefinite,
};

struct NewtonSettings {
    NewtonHessian hessian = NewtonHessian::Projected;
    /// Converged when ‖∇f‖∞ ≤ tolerance · max(1, ‖∇f(x_0)‖∞) …; ∇f in kg·m (f in kg·m²).
    double tolerance = 1e-11;
    /// … and ‖∇f‖∞ ≤ relativeTolerance · ‖∇f(x_0)‖∞. In SI units ∇f is far below 1 kg·m for a
    /// short step (‖∇f(x̃)‖∞ ≈ m_i h² |g| ≈ 1e-9 kg·m at h = 1 ms), where the first test alone is
    /// an absolute 1e-11 that x_0 itself may pass; this one keeps the reference converged at any h.
    /// 1 disables it (the first test alone).
    double relativeTolerance = 1e-8;
    int maxIterations = 100;
    double armijo = 1e-4;   ///< sufficient-decrease constant c₁ in f(x+αd) ≤ f(x) + c₁ α ∇fᵀd
    double backtrack = 0.5; ///< step shrink factor per rejected trial, in (0, 1)
    int maxBacktracks = 40; ///< rejected trials before the solve stops (see above)
    /// Central-difference step for the element Hessians, relative to the tet's size ∛(6 V_e).
    double fdStep = 1e-5;
    /// The solve stops (see above) when ‖α d‖∞ ≤ stepTolerance · max(‖x‖∞, mean tet size).
    double stepTolerance = 1e-15;
    /// When set (non-owning; e.g. a studio preview stopping), the solve ends before its next
    /// iteration with NewtonStatus::Cancelled: a long reference never holds up the one who waits.
    const std::atomic<bool>* cancel = nullptr;
};

/// scale ∂Ψ/∂F(F) Dm⁻ᵀ of tet t at its node positions xe (scale = h² V w for the step's term):
/// column k is the gradient of the term with respect to node k + 1, node 0's is minus their sum.
Mat3 tetTermGradientColumns(const StepProblem& p, size_t t, const std::array<Vec3, 4>& xe, double scale);

/// Throws std::invalid_argument naming the rule that failed, e.g.
/// "sim::solveNewton(): armijo 2 must be in (0, 1)".
void validate(const NewtonSettings& settings);

enum class NewtonStatus {
    Converged,           ///< gradient criterion met
    Stalled,             ///< no further progress while ‖∇f‖∞ is above the absolute test
    MaxIterations,       ///< maxIterations reached before the gradient criterion
    FactorizationFailed, ///< CHOLMOD failed (matrix not positive definite, out of memory, ...)
    NonFinite,           ///< x_0, f or ∇f not finite
    Cancelled,           ///< NewtonSettings::cancel was set; x is where the solve stopped
};

/// "converged", "stalled", "max_iterations", "factorization_failed", "non_finite", "cancelled".
const char* newtonStatusName(NewtonStatus status);

struct NewtonResult {
    NewtonStatus status = NewtonStatus::NonFinite;
    std::string message;    ///< what stopped the solve; empty (or a note) when Converged
    std::vector<Vec3> x;    ///< #V, the last accepted iterate (x* when Converged), metres
    double f = 0;           ///< f(x), kg·m²
    int iterations = 0;     ///< accepted Newton steps
    int projectedSteps = 0; ///< steps taken with the projected Hessian
    /// Per iterate x_0 … x_iterations (iterations + 1 entries each):
    std::vector<double> gradientNorms; ///< ‖∇f(x_k)‖∞, kg·m
    std::vector<double> objectives;    ///< f(x_k), kg·m²
    std::vector<double> seconds;       ///< wall time from the start of the solve to x_k, s
    double totalSeconds = 0;           ///< wall time of the whole solve, s
    bool converged() const { return status == NewtonStatus::Converged; }
};

/// Minimizes problem.objective() starting from x0 (#V, metres). Fixed nodes are set to
/// problem.xTilde and stay there. Throws std::invalid_argument when the problem is inconsistent
/// (array sizes, tet indices, h ≤ 0, no model) or the settings are invalid; everything else is
/// reported through NewtonResult::status.
NewtonResult solveNewton(const StepProblem& problem, const std::vector<Vec3>& x0, const NewtonSettings& settings = {});

} // namespace viscera::sim
