#pragma once
/// Valanis–Landel curves for the studio's curve editor [A §4.3.3, Fig. 4.6–4.7]: presets with
/// few control points that a person can drag, and the small-strain and rest-state figures the
/// editor shows beside them.
///
/// Rest point: every preset curve has a control point at exactly x = 1. The editor pins it, so
/// f′(1), g′(1), h′(1) keep their values and the stress at rest f′(1) + 2g′(1) + h′(1) stays zero
/// while the other points move [A §4.3.3]; Ψ(1, 1, 1) = 0 holds for any curves, since f, g, h are
/// integrated from 1 (valanis_landel.hpp).
#include "sim/material/valanis_landel.hpp"

#include <string>
#include <vector>

namespace viscera::sim {

/// Abscissae of the preset control points (dimensionless). Stretches, and products of two
/// stretches (g′): 12 points over [0.3, 3], 5 of them in [0.7, 1.5]. Volume ratios (h′): 12 points
/// over [0.3, 2.5], 7 of them in [0.85, 1.15] (an almost incompressible tissue keeps J near 1),
/// ending below e ≈ 2.718 so that the Neo-Hookean h′ (peak at J = exp(1 + μ/λ) ≥ e) is
/// strictly increasing over them; beyond the ends the curves continue linearly (curve.hpp).
const std::vector<double>& editableStretchPoints();
const std::vector<double>& editableVolumePoints();

/// The Valanis–Landel form of `law` sampled at the editable points (values exact at the points;
/// between them the curve interpolant of curve.hpp):
///   "neo_hookean":         f′ = μx (StrictlyIncreasing), g′ absent, h′ = (λ log J − μ)/J
///                          (StrictlyIncreasing) [A eq. 4.19–4.20];
///   "st_venant_kirchhoff": f′ = (μ + λ/2)(x³ − x) − λx (Unconstrained: it falls for small x),
///                          g′ = λy/2 (StrictlyIncreasing; absent when λ = 0), h′ absent;
///   "corotated":           f′ = (2μ + λ)(x − 1) − 2λ (StrictlyIncreasing), g′ = λ (constant,
///                          Unconstrained; absent when λ = 0), h′ absent.
/// The linear f′ and g′ and the cubic f′ are reproduced exactly between the points; the
/// Neo-Hookean h′ within 3e-3 (λ + μ) over J in [0.7, 1.5], and the preset's uniaxial stress
/// stays within 0.1 % of the analytic Neo-Hookean's over stretches 0.6–1.6 (E in [1 kPa, 1 MPa],
/// ν in [0.3, 0.499]: 0.08 % at most).
/// Lamé μ = E/(2(1 + ν)), λ = Eν/((1 + ν)(1 − 2ν)). Throws std::invalid_argument for E, ν out of
/// the material limits (as validate(Material) words it: "sim::editableCurves(): poisson_ratio
/// 0.500000 must be in [0, 0.5)") and viscera::InputError for another law name (listing the three).
ValanisLandelCurves editableCurves(const std::string& law, double youngsModulus, double poissonRatio);

/// Small-strain elastic constants of curves (linearization at rest).
struct SmallStrainConstants {
    double shearModulus = 0;  ///< μ_eff = (f″(1) + g″(1) − g′(1) − h′(1))/2 (Pa)
    double lameLambda = 0;    ///< λ_eff = g″(1) + g′(1) + h″(1) + h′(1) (Pa)
    double youngsModulus = 0; ///< E = μ(3λ + 2μ)/(λ + μ) (Pa)
    double poissonRatio = 0;  ///< ν = λ / (2(λ + μ)), in (−1, 0.5)
};

/// From ValanisLandelDensity::shearModulus() and lameLambda(). Throws viscera::InputError when
/// the curves do not make a valid density (ValanisLandelDensity's checks: rest stress, μ > 0,
/// λ + 2μ > 0) or when the bulk modulus λ + 2μ/3 is not positive (then E, ν are undefined).
SmallStrainConstants smallStrainConstants(const ValanisLandelCurves& curves);

/// The rest state of curves, for display [A eq. 4.18].
struct RestNormalization {
    double restEnergy = 0; ///< Ψ(1, 1, 1) = 3f(1) + 3g(1) + h(1) (J/m^3): 0 by construction
    double restStress = 0; ///< f′(1) + 2g′(1) + h′(1) (Pa): the principal stress at rest
    /// ValanisLandelDensity::kRestStressTolerance · max(|f′(1)|, |2g′(1)|, |h′(1)|,
    /// f″(1) + 2g″(1) + h″(1)) (Pa): the bound ValanisLandelDensity accepts.
    double restStressTolerance = 0;
    bool balanced = false; ///< |restStress| ≤ restStressTolerance
};
/// O(1); never throws (absent curves count as zero).
RestNormalization restNormalization(const ValanisLandelCurves& curves);

} // namespace viscera::sim
