#pragma once
/// Error against run time [A §4.4.3, Fig. 4.12]: the relative error
///     e_k = (f(x_k) − f(x*)) / (f(x_0) − f(x*))          [A eq. 4.45]
/// of a solver's iterates x_k on one implicit step, against a converged Newton reference x*, per
/// iteration and against wall time. Plain structs, ready to be written as JSON
/// ("accuracy": [{"frame", "solver", "iterations", "rel_error", "time_ms"}] in the session report).
///
/// Floor: f carries the rest-state constant of the material energy and is summed in double, so
/// e_k below relErrorFloor ≈ 64 ε |f(x*)| / (f(x_0) − f(x*)) is rounding noise, not error. For a
/// very short step (h ≲ 0.2 ms from rest) f(x_0) − f(x*) itself is at that level and the trace
/// cannot measure anything (relErrorFloor ≥ 1).
#include "sim/reference/newton.hpp"
#include "sim/xpbd/step_problem.hpp"
#include "sim/xpbd/xpbd_solver.hpp"

#include <string>
#include <vector>

namespace viscera::sim {

struct AccuracyTrace {
    std::string solver;           ///< e.g. "xpbd", "newton"
    std::vector<int> iterations;  ///< k, from 0 (x_0) up
    std::vector<double> relError; ///< e_k, dimensionless (1 at k = 0, 0 at x*)
    std::vector<double> timeMs;   ///< solver wall time from x_0 to x_k, ms (0 at k = 0)
    double fStar = 0;             ///< f(x*), kg·m²
    double f0 = 0;                ///< f(x_0), kg·m²
    double h = 0;                 ///< step of the measured problem, s
    double relErrorFloor = 0;     ///< rounding-noise level of relError (see above)
    // The reference solve behind fStar.
    std::string referenceStatus;      ///< newtonStatusName()
    int referenceIterations = 0;      ///< Newton iterations
    double referenceGradientNorm = 0; ///< ‖∇f(x*)‖∞, kg·m
    double referenceMs = 0;           ///< wall time of the reference solve, ms
};

/// Index of the first entry with relError ≤ threshold, or −1 when none reaches it.
int firstBelow(const AccuracyTrace& trace, double threshold);

/// Turns an iterate stream (k, x_k, seconds) into an AccuracyTrace. Non-copyable view: the
/// problem must outlive the recorder. Cost per observation: one f evaluation, O(#V + #T).
class AccuracyRecorder {
public:
    /// x0: the stream's starting point (#V); recorded as k = 0 at 0 ms. Throws
    /// std::invalid_argument when x0 or reference.x does not match the problem's node count.
    AccuracyRecorder(std::string solver, const StepProblem& problem, const NewtonResult& reference,
                     const std::vector<Vec3>& x0);
    AccuracyRecorder(const AccuracyRecorder&) = delete;
    AccuracyRecorder& operator=(const AccuracyRecorder&) = delete;

    /// Records iterate k (k ≥ 1, increasing; a k = 0 observation is ignored, x_0 is already
    /// recorded) reached after `seconds` of solver time since x_0. Throws std::invalid_argument on
    /// a size mismatch or a k that does not increase.
    void observe(int k, const std::vector<Vec3>& xk, double seconds);

    const AccuracyTrace& trace() const { return m_trace; }
    AccuracyTrace take() { return std::move(m_trace); }

private:
    const StepProblem& m_problem;
    AccuracyTrace m_trace;
};

/// XPBD on the problem of the solver's next substep (XpbdSolver::nextSubstepProblem(): h =
/// dt / substeps, from its current state): a Newton reference from x̃, then `maxIterations`
/// production sweeps from x_0 = x̃, λ = 0 (XpbdSolver::iterateOn()), one trace entry per sweep,
/// timed by the sweeps alone. Entry k is what the setting "substeps × k iterations" computes for
/// this substep (with 1 substep: for the frame). XPBD's e_k levels off above 0 after a few sweeps, at a level set by h:
/// its fixed point is not x* (XPBD drops the g-residual of [A eq. 4.41]; measured 1.4e-2 at h = 0.83 ms, 2.4e-5 at h =
/// 0.17 ms on a 4,944-tet body, bench/bench_accuracy.cpp). The solver's state is untouched. Throws
/// std::invalid_argument when maxIterations < 1 or the settings are invalid. Cost: one Newton solve plus the sweeps
/// plus one f evaluation per sweep.
/// chebyshevRho: XpbdIteration::Chebyshev's rho (the trace is then named "xpbd-chebyshev").
AccuracyTrace measureXpbd(const XpbdSolver& solver, int maxIterations, const NewtonSettings& settings = {},
                          XpbdIteration mode = XpbdIteration::Standard, double chebyshevRho = 0.0);

/// Newton's own iterates on `problem` from x_0 = x̃, measured against its final iterate
/// (Fig. 4.12 "newton direct"); the last entry is 0 when the solve converged. Entries stop where
/// the solve stopped; referenceStatus says why (no entries at all when x̃ is not finite).
AccuracyTrace measureNewton(const StepProblem& problem, const NewtonSettings& settings = {});
/// The same on the problem of the solver's next substep.
AccuracyTrace measureNewton(const XpbdSolver& solver, const NewtonSettings& settings = {});

} // namespace viscera::sim
