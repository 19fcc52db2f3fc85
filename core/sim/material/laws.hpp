#pragma once
/// The classic isotropic laws of [A Table 4.1] as energy densities with analytic Ψ and P, and
/// their Valanis–Landel forms [A §4.3.2] where the law has one.
///
/// All take Lamé parameters μ > 0, λ ≥ 0 (Pa) and throw std::invalid_argument otherwise; all
/// have Ψ(I) = 0, P(I) = 0, restStiffness() = λ + 2μ, and are finite for every finite F. Each
/// also offers psiAndStress() (CombinedEnergyDensity), bit-identical to psi() and stress() and
/// sharing their work (one signed SVD for corotated, one log J for Neo-Hookean).
///
/// Corrections to the table as printed: the corotated energy is μ‖F − R‖² + λ/2 tr²(RᵀF − I)
/// (the table's "2/λ" is a typo; its stress column matches λ/2), and the Neo-Hookean stress is
/// μ(F − F⁻ᵀ) + λ log J F⁻ᵀ (the table repeats μ inside the bracket).
#include "sim/material/valanis_landel.hpp"

#include <memory>

namespace viscera::sim {

/// Linear (small-strain) elasticity: ε = ½(F + Fᵀ) − I, Ψ = μ ε:ε + λ/2 tr²ε,
/// P = 2μ ε + λ tr(ε) I. Not rotation invariant (Ψ(RF) ≠ Ψ(F)); no Valanis–Landel form.
class LinearElasticDensity final : public EnergyDensity, public CombinedEnergyDensity {
public:
    LinearElasticDensity(double mu, double lambda);
    std::string name() const override { return "linear"; }
    double psi(const Mat3& F) const override;
    Mat3 stress(const Mat3& F) const override;
    double psiAndStress(const Mat3& F, Mat3& P) const override;
    double restStiffness() const override { return m_lambda + 2.0 * m_mu; }

private:
    double m_mu, m_lambda;
};

/// St. Venant–Kirchhoff: E = ½(FᵀF − I), Ψ = μ E:E + λ/2 tr²E, P = F(2μE + λ tr(E) I).
/// Rotation invariant but blind to inversion (Ψ depends on FᵀF only) and soft under strong
/// compression.
class StVenantKirchhoffDensity final : public EnergyDensity, public CombinedEnergyDensity {
public:
    StVenantKirchhoffDensity(double mu, double lambda);
    std::string name() const override { return "st_venant_kirchhoff"; }
    double psi(const Mat3& F) const override;
    Mat3 stress(const Mat3& F) const override;
    double psiAndStress(const Mat3& F, Mat3& P) const override;
    double restStiffness() const override { return m_lambda + 2.0 * m_mu; }

private:
    double m_mu, m_lambda;
};

/// Corotated linear: R = U Vᵀ from signedSvd() (a proper rotation, also for inverted F),
/// Ψ = μ‖F − R‖² + λ/2 tr²(RᵀF − I) = μ Σ(σi − 1)² + λ/2 (Σσi − 3)²,
/// P = 2μ(F − R) + λ tr(RᵀF − I) R.
class CorotatedLinearDensity final : public EnergyDensity, public CombinedEnergyDensity {
public:
    CorotatedLinearDensity(double mu, double lambda);
    std::string name() const override { return "corotated"; }
    double psi(const Mat3& F) const override;
    Mat3 stress(const Mat3& F) const override;
    double psiAndStress(const Mat3& F, Mat3& P) const override;
    double restStiffness() const override { return m_lambda + 2.0 * m_mu; }

private:
    double m_mu, m_lambda;
};

/// Compressible Neo-Hookean: Ψ = μ/2 (tr FᵀF − 3) + φ(J), φ(J) = −μ log J + λ/2 (log J)²,
/// P = μF + φ′(J) cof(F) (= μ(F − F⁻ᵀ) + λ log J F⁻ᵀ for J > 0).
/// log J extension: for J < jMin, φ is replaced by its second-order Taylor polynomial at jMin
/// (C2 there, φ″(jMin) = (μ + λ(1 − log jMin))/jMin² > 0), so Ψ and P stay finite and smooth for
/// J ≤ 0 and keep growing as the element inverts.
class NeoHookeanDensity final : public EnergyDensity, public CombinedEnergyDensity {
public:
    static constexpr double kDefaultJMin = 1e-2;
    /// jMin in (0, 1); throws std::invalid_argument otherwise.
    NeoHookeanDensity(double mu, double lambda, double jMin = kDefaultJMin);
    std::string name() const override { return "neo_hookean"; }
    double psi(const Mat3& F) const override;
    Mat3 stress(const Mat3& F) const override;
    double psiAndStress(const Mat3& F, Mat3& P) const override;
    double restStiffness() const override { return m_lambda + 2.0 * m_mu; }
    double jMin() const { return m_jMin; }

private:
    /// φ(J) and φ′(J) (one logarithm).
    void phi(double J, double& value, double& slope) const;
    double m_mu, m_lambda, m_jMin;
};

/// "linear", "st_venant_kirchhoff", "corotated" or "neo_hookean" (default parameters). Throws
/// viscera::InputError for another name (listing the supported ones), std::invalid_argument for
/// bad μ, λ.
std::unique_ptr<EnergyDensity> makeEnergyDensity(const std::string& name, double mu, double lambda);

/// St. Venant–Kirchhoff in Valanis–Landel form (signed stretches, exact):
///   f(x) = (μ + λ/2)(x² − 1)²/4 − λ/2 (x² − 1),  g(y) = λ/4 (y² − 1),  h = 0,
///   f′(x) = (μ + λ/2)(x³ − x) − λx,  g′(y) = λ/2 y.
/// f′ is a cubic that falls for |x| < sqrt((2μ + 3λ)/(6μ + 3λ)) (StVK's compression weakness), so
/// it is Unconstrained; the curves are sampled uniformly on x in [−4, 4], y in [−16, 16] and are
/// exact there (the interpolant reproduces cubics), linear beyond. g is absent when λ = 0.
ValanisLandelCurves stVenantKirchhoffCurves(double mu, double lambda);

/// Corotated linear in Valanis–Landel form (exact everywhere, both curves are linear):
///   f(x) = (μ + λ/2)(x − 1)² − 2λ(x − 1),  g(y) = λ(y − 1),  h = 0,
///   f′(x) = (2μ + λ)(x − 1) − 2λ (StrictlyIncreasing),  g′(y) = λ (constant: Unconstrained;
///   absent when λ = 0).
ValanisLandelCurves corotatedCurves(double mu, double lambda);

/// The Valanis–Landel form of a law named as in makeEnergyDensity(): "st_venant_kirchhoff",
/// "corotated", "neo_hookean" (neoHookeanCurves() with default options). Throws
/// viscera::InputError for "linear" (not rotation invariant, so no such form) and unknown names.
ValanisLandelCurves valanisLandelCurves(const std::string& name, double mu, double lambda);

} // namespace viscera::sim
