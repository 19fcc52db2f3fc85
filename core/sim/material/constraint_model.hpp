#pragma once
/// How a hyperelastic material becomes XPBD tet constraints [A §4.4.2].
///
/// A model maps the deformation gradient F of a tet to at most kMaxTetConstraints scalar
/// constraints C_k(F) with compliances α_k (per unit rest volume, 1/Pa), so that the elastic
/// energy of a tet with rest volume V and stiffness weight w is
///     E(F) = V · Σ_k C_k(F)² / (2 α_k / w),
/// the XPBD energy ½ Cᵀ α⁻¹ C of [A eq. 4.36]. The Newton reference minimizes exactly this energy,
/// so XPBD and the reference solve the same implicit step.
///
/// Two families:
///   - StableNeoHookeanModel: C_D = |F|_F (α = 1/μ) and C_H = det F − γ (α = 1/λ), γ = 1 + μ/λ,
///     solved as one coupled 2×2 block (rest-stable, inversion-safe);
///   - EnergyConstraintModel: one constraint C = sqrt(2 Ψ(F)) with α = 1 for any energy density
///     Ψ ≥ 0 with Ψ(I) = 0 (linear, StVK, corotated, Valanis–Landel curves).
#include <Eigen/Core>

#include <array>
#include <memory>
#include <string>

namespace viscera::sim {

using Mat3 = Eigen::Matrix3d;
inline constexpr int kMaxTetConstraints = 2;

/// Isotropic hyperelastic energy density Ψ(F) (J/m^3) and first Piola–Kirchhoff stress
/// P = ∂Ψ/∂F (Pa). Implementations must be finite for every finite F, inverted ones included.
class EnergyDensity {
public:
    virtual ~EnergyDensity() = default;
    virtual std::string name() const = 0;
    virtual double psi(const Mat3& F) const = 0;
    virtual Mat3 stress(const Mat3& F) const = 0;
    /// Small-strain stiffness scale (Pa), e.g. λ + 2μ; used for stability checks at load.
    virtual double restStiffness() const = 0;
};

struct TetConstraintValues {
    int count = 0;
    std::array<double, kMaxTetConstraints> C{};
    std::array<Mat3, kMaxTetConstraints> dCdF{}; ///< ∂C_k/∂F
};

class TetConstraintModel {
public:
    virtual ~TetConstraintModel() = default;
    virtual std::string name() const = 0;
    virtual int count() const = 0;
    /// α_k per unit rest volume (1/Pa); 0 means a hard constraint.
    virtual std::array<double, kMaxTetConstraints> compliance() const = 0;
    /// Constraint values and their gradients with respect to F. Never throws; a constraint whose
    /// gradient is undefined at F (e.g. sqrt(2Ψ) exactly at rest) reports C = 0, dCdF = 0.
    virtual void evaluate(const Mat3& F, TetConstraintValues& out) const = 0;
    /// Energy density Σ_k C_k² / (2 α_k) (J/m^3) and its gradient with respect to F.
    double energyDensity(const Mat3& F) const;
    Mat3 energyDensityGradient(const Mat3& F) const;
    /// Small-strain stiffness scale (Pa), for stability checks.
    virtual double restStiffness() const = 0;
};

} // namespace viscera::sim
