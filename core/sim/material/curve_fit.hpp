#pragma once
/// Least-squares fit of Valanis–Landel curves to uniaxial test data [A §4.3.3: "This curve based
/// editing system can also fit the material to experimental data which is generated from
/// uni-axial tension and compression test"].
///
/// Unknowns: the control VALUES of f′ (and optionally h′); the control points' x stay where they
/// are, and the point at x = 1 of every fitted curve keeps its value (pinned, as the editor pins
/// it), so f′(1) + 2g′(1) + h′(1), the stress at rest, is exactly that of the start curves. g′
/// and any curve not fitted stay as given (h′ under FitCurves::FPrimeKeepingPoisson: scaled).
///
/// Shape rule by parametrization: a StrictlyIncreasing curve is written as its pinned rest value
/// plus positive increments between neighbouring points, y_{k+1} − y_k = exp(θ_k), so any θ gives
/// a strictly increasing curve; θ_k is kept within ±30 of log(curve scale) (projection), so an
/// increment never drops below ~1e-13 of the curve's scale (no ties by rounding). An
/// Unconstrained curve has θ_k = (y_k − y_rest)/scale. scale = the largest |y| of the start
/// curve's control points, or its slope |y′(1)| when that is larger (Pa).
///
/// Method: Levenberg–Marquardt (Marquardt scaling diag(JᵀJ), floored at 1e-12 of its largest
/// entry; Nielsen's damping update; a step changing any θ by more than 3 counts as rejected) on
/// the residuals r_i = (σ(λ_i) − σ_i) w_i, w_i = 1 (FitWeighting::Absolute) or
/// 1/max(|σ_i|, floor) (Relative), with σ(λ) the uniaxial nominal stress of the trial curves
/// (material_response.hpp, warm-started from the last accepted lateral stretches) and a
/// forward-difference Jacobian (step 1e-6 max(1, |θ|)). In two phases:
///   1. scale: one unknown per fitted curve, s_c, multiplying the curve's deviations from its
///      rest value by e^{s_c} (the start's shape at the data's stiffness; well posed), at most
///      30 iterations;
///   2. full: every θ, with the residuals sqrt(ρ S) (θ − θ₁) added (θ₁ the phase-1 result,
///      ρ = FitOptions::regularization, S = Σ (w_i σ_i)²). Uniaxial data fix one function of
///      stretch while f′ and h′ are two, and control points near the data's edge act only
///      through the interpolant's slopes: the pull keeps those directions at the phase-1 shape
///      instead of letting them wander (on exact Neo-Hookean data, 41 points: with ρ = 1e-6
///      25–50 iterations to errors below 0.1 %; with ρ = 0 often 100 iterations without
///      converging, errors up to 2 %; without phase 1, increments run to e^{±30}, errors 10–20 %).
/// A trial step is rejected, and the damping raised, when the trial curves are not a valid
/// density (ValanisLandelDensity's checks), when a data point has no uniaxial state, or when
/// any residual is not finite: the result is never NaN. Deterministic (no randomness, no
/// threads); at most FitOptions::maxIterations Jacobians in all.
///
/// Cost: one residual evaluation ≈ #data uniaxial solves (~0.3 µs each) + two curve rebuilds;
/// one iteration ≈ (#unknowns + 1) evaluations. 41 points, f′ and h′ (22 unknowns): 25–50
/// iterations, 250–600 evaluations, 10–50 ms.
#include "sim/material/uniaxial_data.hpp"
#include "sim/material/valanis_landel.hpp"

#include <vector>

namespace viscera::sim {

enum class FitCurves {
    FPrime,          ///< f′ only (h′, g′ as given: the volume stiffness λ is kept, so ν follows μ)
    FPrimeAndHPrime, ///< f′ and h′ (g′ as given); the start needs an h′
    /// f′ only, with the small-strain ν of the start kept: h′ follows the fitted shear stiffness,
    /// its deviations from h′(1) scaled by the one factor k > 0 that makes λ_eff/μ_eff the
    /// start's, k = 1 + (λ₀/μ₀ · μ_eff − λ_eff)/h″(1) (λ_eff, μ_eff of f′ fitted and h′ as
    /// given; editable_curves.hpp, SmallStrainConstants), so ν is the start's up to rounding
    /// however stiff the data. g′ as given. The start needs an h′ with h″(1) > 0 (every
    /// Neo-Hookean preset has one); a trial whose k would not be positive is not admissible.
    FPrimeKeepingPoisson,
};

enum class FitWeighting {
    Absolute, ///< minimize Σ (σ_fit − σ_data)² (Pa²)
    Relative, ///< minimize Σ ((σ_fit − σ_data)/max(|σ_data|, floor))² (see CurveFitResult)
};

struct FitOptions {
    FitCurves curves = FitCurves::FPrimeAndHPrime;
    FitWeighting weighting = FitWeighting::Absolute;
    int maxIterations = 100; ///< Levenberg–Marquardt iterations of both phases (one Jacobian each), ≥ 1
    /// Converged when an accepted step lowers the cost by less than this fraction (and the
    /// model predicted no more), when the step is below this relative to θ, or when the
    /// gradient vanishes (‖Jᵀr‖∞ ≤ tolerance · cost scale).
    double tolerance = 1e-10;
    /// ρ ≥ 0: pull of phase 2 toward the phase-1 curves (see the file comment). A change of
    /// one θ by 1 costs ρ S, S = Σ (w_i σ_i)²: 1e-6 of the data's weighted energy.
    double regularization = 1e-6;
};

enum class FitStop {
    CostTolerance,     ///< relative cost decrease below FitOptions::tolerance
    StepTolerance,     ///< step below FitOptions::tolerance relative to the parameters
    GradientTolerance, ///< gradient below tolerance (an exact fit included)
    /// No trial step lowered the cost up to the largest damping (1e16): stationary within the
    /// precision of the finite-difference Jacobian (the usual end on exact data).
    NoDescent,
    IterationLimit, ///< FitOptions::maxIterations reached (not converged)
};

struct CurveFitResult {
    ValanisLandelCurves curves;       ///< the fitted curves (same points, shapes and names)
    std::vector<double> fittedStress; ///< σ_fit at each data stretch (#rows), Pa
    double sse = 0;                   ///< Σ (σ_fit − σ_data)² (Pa²)
    double rSquared = 0; ///< 1 − SSE/SST, SST = Σ (σ_data − mean)²; 1 − SSE/(SSE + 1) when SST = 0
    /// max_i |σ_fit − σ_data| / max(|σ_data|, relativeErrorFloor).
    double maxRelativeError = 0;
    /// 1e-3 · max_i |σ_data| (1 Pa when every σ_data is 0): near λ = 1 the data stress is ~0 and
    /// its own noise, so errors there are measured against 0.1 % of the largest stress.
    double relativeErrorFloor = 0;
    double stretchMin = 0, stretchMax = 0; ///< stretch range of the data (where the fit holds)
    int iterations = 0;                    ///< Jacobians computed
    int evaluations = 0;                   ///< residual evaluations (Jacobian columns and trial steps)
    FitStop stop = FitStop::IterationLimit;
    bool converged = false; ///< stop != IterationLimit
};

/// Fits `start`'s control values to `data` (see the file comment). Rows marked with another test
/// (UniaxialData::loadCase, combineTests: equibiaxial, planar shear) are fitted with that test's
/// nominal stress (material_response.hpp, solveLoadCase): a second test pins what one uniaxial
/// test leaves free (the volume response, so h′ and ν). Throws std::invalid_argument
/// for a broken precondition (data with fewer than UniaxialDataLimits::minRows rows, lengths
/// that differ, stretches not finite, positive and strictly increasing within a test, stresses not finite,
/// named by 0-based row: "sim::fitUniaxial(): data row 4: stretch 1.02 must be ...";
/// maxIterations < 1; tolerance not positive; regularization negative; no f′, no h′ with FPrimeAndHPrime, no h′
/// rising at 1 with FPrimeKeepingPoisson; a fitted
/// curve without a control point at x = 1) and viscera::InputError when the start curves are
/// not a valid density or have no uniaxial state at a data stretch ("sim::fitUniaxial(): start
/// curves: no uniaxial state at stretch 3 (data line 12)").
CurveFitResult fitUniaxial(const ValanisLandelCurves& start, const UniaxialData& data, const FitOptions& options = {});

} // namespace viscera::sim
