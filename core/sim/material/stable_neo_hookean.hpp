#pragma once
/// Stable Neo-Hookean as two XPBD constraints (see constraint_model.hpp):
///   C_D = |F|_F,        α_D = 1/μ
///   C_H = det F − γ,    α_H = 1/λ,   γ = 1 + μ/λ
/// Energy density μ/2 |F|² + λ/2 (J − γ)² = Ψ_SNH(F) + 3μ/2 + μ²/(2λ): the stable Neo-Hookean
/// energy up to a constant, zero stress at F = I, finite and smooth through inversion (J < 0).
#include "sim/material/constraint_model.hpp"

namespace viscera::sim {

class StableNeoHookeanModel final : public TetConstraintModel {
public:
    /// Lamé parameters in Pa; throws std::invalid_argument unless mu > 0 and lambda > 0.
    StableNeoHookeanModel(double mu, double lambda);
    std::string name() const override { return "stable_neo_hookean"; }
    int count() const override { return 2; }
    std::array<double, kMaxTetConstraints> compliance() const override { return {1.0 / m_mu, 1.0 / m_lambda}; }
    void evaluate(const Mat3& F, TetConstraintValues& out) const override;
    double restStiffness() const override { return m_lambda + 2.0 * m_mu; }
    double mu() const { return m_mu; }
    double lambda() const { return m_lambda; }
    double gamma() const { return m_gamma; }

private:
    double m_mu, m_lambda, m_gamma;
};

} // namespace viscera::sim
