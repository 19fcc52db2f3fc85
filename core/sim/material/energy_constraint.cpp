#include "sim/material/energy_constraint.hpp"

#include <cmath>
#include <stdexcept>

namespace viscera::sim {

EnergyConstraintModel::EnergyConstraintModel(std::shared_ptr<const EnergyDensity> density)
    : m_density(std::move(density)) {
    if (!m_density) throw std::invalid_argument("sim::EnergyConstraintModel(): density is null");
    m_restEnergy = kRestEnergyTolerance * std::abs(m_density->restStiffness());
}

void EnergyConstraintModel::evaluate(const Mat3& F, TetConstraintValues& out) const {
    out.count = 1;
    const double psi = m_density->psi(F);
    if (!(psi > m_restEnergy)) {
        out.C[0] = 0.0;
        out.dCdF[0].setZero();
        return;
    }
    const double C = std::sqrt(2.0 * psi);
    out.C[0] = C;
    out.dCdF[0] = m_density->stress(F) / C;
}

} // namespace viscera::sim
