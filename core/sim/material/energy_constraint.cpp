#include "sim/material/energy_constraint.hpp"

#include <cmath>
#include <stdexcept>

namespace viscera::sim {

EnergyConstraintModel::EnergyConstraintModel(std::shared_ptr<const EnergyDensity> density)
    : m_density(std::move(density)) {
    if (!m_density) throw std::invalid_argument("sim::EnergyConstraintModel(): density is null");
    m_restEnergy = kRestEnergyTolerance * std::abs(m_density->restStiffness());
    m_combined = dynamic_cast<const CombinedEnergyDensity*>(m_density.get());
}

void EnergyConstraintModel::evaluate(const Mat3& F, TetConstraintValues& out) const {
    out.count = 1;
    Mat3 P;
    const double psi = m_combined ? m_combined->psiAndStress(F, P) : m_density->psi(F);
    if (!(psi > m_restEnergy)) {
        out.C[0] = 0.0;
        out.dCdF[0].setZero();
        return;
    }
    const double C = std::sqrt(2.0 * psi);
    out.C[0] = C;
    if (!m_combined) P = m_density->stress(F);
    out.dCdF[0] = P * (1.0 / C);
}

} // namespace viscera::sim
