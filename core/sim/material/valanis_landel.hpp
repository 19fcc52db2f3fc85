#pragma once
/// Valanis–Landel energy densities edited through response curves [A §4.3.2–4.3.3].
///
///     Ψ(λ1, λ2, λ3) = Σ_i f(λi) + Σ_{i<j} g(λi λj) + h(λ1 λ2 λ3)            [A eq. 4.15]
///
/// λi are the signed principal stretches of F (signedSvd()), and f, g, h are the integrals of the
/// authored curves f′, g′, h′ (Pa) from the rest state, f(x) = ∫₁ˣ f′ (same for g, h), so that
/// f(1) = g(1) = h(1) = 0 and Ψ(I) = 0: the rest-state normalization of [A §4.3.3] (eq. 4.18).
/// Stress in the principal frame [A eq. 4.16–4.17]:
///     ∂Ψ/∂λ1 = f′(λ1) + λ2 g′(λ1λ2) + λ3 g′(λ1λ3) + λ2λ3 h′(J),  (cyclic),
///     P = U diag(∂Ψ/∂λi) Vᵀ.
///
/// Inversion: λ3 (and J) are negative for an inverted element. The curves continue linearly
/// beyond their first and last control points (see curve.hpp), so f, g and h are quadratics
/// there and Ψ, P are finite for every finite F (J ≤ 0 included). For an h′ whose first slope is
/// positive (every StrictlyIncreasing curve, the Neo-Hookean preset) h keeps growing as J
/// decreases through 0, so inversion is penalized, not rewarded.
#include "sim/material/constraint_model.hpp"
#include "sim/material/curve.hpp"
#include "sim/material/energy_constraint.hpp"

#include <optional>

namespace viscera::sim {

/// F = U diag(sigma) Vᵀ with U, V proper rotations (det = +1), σ1 ≥ σ2 ≥ |σ3| and
/// sign(σ3) = sign(det F): the rotation-variant SVD of Irving et al. 2004.
///
/// Method (no iteration, no allocation, ~70 ns): V from the eigenvectors of FᵀF, computed
/// directly. The extreme eigenvalue farthest from the mean (always separated from the other two
/// by at least √3 times their spread scale) comes from the trigonometric-form cubic, solved by
/// a polynomial fit and a Halley step; its eigenvector from the largest cross product of rows of
/// FᵀF − λI; the other two from an exact 2×2 rotation in its orthogonal complement, so repeated
/// and nearly repeated singular values (rest, uniaxial and isotropic states) are as accurate as
/// distinct ones. Then U = F V diag(1/σ) with u3 = u1 × u2 and σ3 = u3 · F v3 (signed); when
/// σ2 < 1e-3 σ1 (rank ≤ 1 or nearly so), Gram–Schmidt and any unit vector orthogonal to u1
/// complete U instead. F is scaled by a power of two when max|F_ij| is outside [2^-60, 2^60].
/// Backward stable: U diag(σ) Vᵀ = F within ~1e-15 |F|, U and V orthonormal within ~1e-15.
struct SignedSvd {
    Mat3 U;
    Eigen::Vector3d sigma; ///< signed principal stretches, dimensionless
    Mat3 V;
};
SignedSvd signedSvd(const Mat3& F);

/// The authored curves; an absent curve means that term is zero.
struct ValanisLandelCurves {
    std::optional<MonotoneCurve> fPrime; ///< f′(λ) (Pa) of one principal stretch λ
    std::optional<MonotoneCurve> gPrime; ///< g′(λiλj) (Pa) of a product of two stretches
    std::optional<MonotoneCurve> hPrime; ///< h′(J) (Pa) of the volume ratio J = λ1λ2λ3
};

class ValanisLandelDensity final : public EnergyDensity, public CombinedEnergyDensity {
public:
    /// Relative tolerance of the rest-stress check f′(1) + 2g′(1) + h′(1) = 0.
    static constexpr double kRestStressTolerance = 1e-9;

    /// `materialName` names the material in messages ("material 'liver': curve h': ...").
    /// Throws viscera::InputError when a curve is invalid, when the stress at rest
    /// f′(1) + 2g′(1) + h′(1) is not zero within kRestStressTolerance · scale (scale = the
    /// largest of |f′(1)|, |2g′(1)|, |h′(1)| and restStiffness()), or when the small-strain
    /// stiffness (restStiffness(), shearModulus()) is not positive.
    ValanisLandelDensity(std::string materialName, ValanisLandelCurves curves);

    std::string name() const override { return "valanis_landel"; }
    double psi(const Mat3& F) const override;  ///< J/m^3
    Mat3 stress(const Mat3& F) const override; ///< first Piola–Kirchhoff P (Pa)
    /// Ψ and P from one signedSvd() and one lookup per curve term (the h′ segment lookup
    /// starts from det F and overlaps the SVD). psi(), stress() and psiAndStress() give
    /// bit-identical results.
    double psiAndStress(const Mat3& F, Mat3& P) const override;
    /// f″(1) + 2g″(1) + h″(1) = λ_eff + 2μ_eff (Pa).
    double restStiffness() const override { return m_restStiffness; }
    /// Small-strain shear modulus μ_eff = (f″(1) + g″(1) − g′(1) − h′(1)) / 2 (Pa).
    double shearModulus() const { return m_shearModulus; }
    /// Small-strain Lamé λ_eff = g″(1) + g′(1) + h″(1) + h′(1) (Pa).
    double lameLambda() const { return m_restStiffness - 2.0 * m_shearModulus; }

    /// Ψ and ∂Ψ/∂λi as functions of signed principal stretches.
    double psiPrincipal(const Eigen::Vector3d& s) const;
    Eigen::Vector3d stressPrincipal(const Eigen::Vector3d& s) const;

    const ValanisLandelCurves& curves() const { return m_curves; }
    const std::string& materialName() const { return m_materialName; }

private:
    /// Ψ at signed stretches s, with hJ = h′ and h at J = s1 s2 s3 (zero when h′ is absent);
    /// writes ∂Ψ/∂s_i into d when d is not null.
    double principal(const Eigen::Vector3d& s, const MonotoneCurve::Sample& hJ, Eigen::Vector3d* d) const;
    /// Ψ(F), and P(F) into P when not null: the one path behind psi(), stress(), psiAndStress().
    double evaluate(const Mat3& F, Mat3* P) const;

    std::string m_materialName;
    ValanisLandelCurves m_curves;
    double m_restStiffness = 0, m_shearModulus = 0;
};

/// Sampling of the Neo-Hookean preset curves.
struct NeoHookeanCurveOptions {
    /// f′(x) = μ x over stretches [stretchMin, stretchMax]; linear, so reproduced exactly (and
    /// extrapolated exactly) by any point count.
    double stretchMin = 0.1, stretchMax = 10.0;
    int stretchCount = 9;
    /// h′(J) = (λ log J − μ) / J over J in [volumeMin, volumeMax], geometric spacing; below
    /// volumeMin h′ continues linearly (h quadratic, finite through J ≤ 0).
    double volumeMin = 1e-2, volumeMax = 1e2;
    int volumeCount = 1201; ///< 300 per decade: h′ within ~1e-9 · max(μ + λ, |h′|)
};

/// Compressible Neo-Hookean Ψ = μ/2 (I₁ − 3) − μ log J + λ/2 (log J)² in Valanis–Landel form
/// [A eq. 4.19–4.20]: f(x) = μ/2 (x² − 1), g = 0, h(J) = −μ log J + λ/2 (log J)², fitted with
/// MonotoneCurve::fit. f′ is StrictlyIncreasing. h′ = (λ log J − μ)/J rises only up to
/// J = exp(1 + μ/λ) and falls beyond it, so h′ is StrictlyIncreasing when volumeMax is below that
/// peak and Unconstrained otherwise (the default range reaches J = 100). Beyond volumeMax h′
/// continues linearly with its negative end slope and crosses zero near J ≈ 2.3 · volumeMax
/// (λ = 10μ), past which Ψ would decrease with J: keep volumeMax above the volume ratios a
/// simulation reaches (the default allows a stretch of 4.6 in every direction).
/// Lamé μ > 0, λ ≥ 0 (Pa); throws std::invalid_argument otherwise.
ValanisLandelCurves neoHookeanCurves(double mu, double lambda, const NeoHookeanCurveOptions& options = {});

} // namespace viscera::sim
