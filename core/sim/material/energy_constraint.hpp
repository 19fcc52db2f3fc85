#pragma once
/// Any energy density as one XPBD tet constraint (see constraint_model.hpp):
///     C = sqrt(2 Ψ(F)),   α = 1,   ∂C/∂F = P / C,
/// so that C² / (2α) = Ψ and the model energy gradient is P. Where Ψ ≤ kRestEnergyTolerance ·
/// restStiffness() (at and near rest, or a density that dips below zero) the constraint reports
/// C = 0 and ∂C/∂F = 0: the gradient of sqrt(2Ψ) is undefined at rest and Ψ there is rounding
/// noise (strains below ~1e-7).
///
/// Cost per evaluate(): one CombinedEnergyDensity::psiAndStress() when the density offers it (all
/// densities of laws.hpp and valanis_landel.hpp do), else psi() and stress(); then a square root
/// and one division.
#include "sim/material/constraint_model.hpp"

#include <memory>

namespace viscera::sim {

/// A density that evaluates Ψ and P from one decomposition of F (one signed SVD for the
/// Valanis–Landel and corotated laws, one determinant and logarithm for Neo-Hookean).
/// Implemented next to EnergyDensity by the densities of laws.hpp and valanis_landel.hpp;
/// EnergyConstraintModel detects it once at construction and then makes one call per tet.
class CombinedEnergyDensity {
public:
    virtual ~CombinedEnergyDensity() = default;
    /// Returns Ψ(F) (J/m^3) and writes P(F) (Pa): bit-identical to psi(F) and stress(F).
    virtual double psiAndStress(const Mat3& F, Mat3& P) const = 0;
};

class EnergyConstraintModel final : public TetConstraintModel {
public:
    /// Energy below this fraction of restStiffness() (J/m^3 per Pa) counts as rest.
    static constexpr double kRestEnergyTolerance = 1e-14;

    /// Shares the density (it is immutable); throws std::invalid_argument when null.
    explicit EnergyConstraintModel(std::shared_ptr<const EnergyDensity> density);

    /// "energy:<density name>", e.g. "energy:neo_hookean".
    std::string name() const override { return "energy:" + m_density->name(); }
    int count() const override { return 1; }
    /// {1, 1}: α = 1 for the one constraint; the second entry is unused (count() = 1).
    std::array<double, kMaxTetConstraints> compliance() const override { return {1.0, 1.0}; }
    void evaluate(const Mat3& F, TetConstraintValues& out) const override;
    double restStiffness() const override { return m_density->restStiffness(); }
    const EnergyDensity& density() const { return *m_density; }

private:
    std::shared_ptr<const EnergyDensity> m_density;
    const CombinedEnergyDensity* m_combined = nullptr; ///< m_density's fused path, if it has one
    double m_restEnergy;                               ///< kRestEnergyTolerance · restStiffness()
};

} // namespace viscera::sim
