#include "sim/material/stable_neo_hookean.hpp"

#include <Eigen/Geometry>

#include <cmath>
#include <stdexcept>

namespace viscera::sim {

StableNeoHookeanModel::StableNeoHookeanModel(double mu, double lambda) : m_mu(mu), m_lambda(lambda) {
    if (!(mu > 0) || !(lambda > 0) || !std::isfinite(mu) || !std::isfinite(lambda))
        throw std::invalid_argument("sim::StableNeoHookeanModel(): mu and lambda must be positive and finite");
    m_gamma = 1.0 + mu / lambda;
}

void StableNeoHookeanModel::evaluate(const Mat3& F, TetConstraintValues& out) const {
    out.count = 2;
    const double norm = F.norm();
    out.C[0] = norm;
    out.dCdF[0] = norm > 0 ? Mat3(F / norm) : Mat3::Zero();
    out.C[1] = F.determinant() - m_gamma;
    out.dCdF[1].col(0) = F.col(1).cross(F.col(2));
    out.dCdF[1].col(1) = F.col(2).cross(F.col(0));
    out.dCdF[1].col(2) = F.col(0).cross(F.col(1));
}

} // namespace viscera::sim
