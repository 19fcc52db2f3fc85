#include "sim/xpbd/xpbd_solver.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace viscera::sim {

std::string validate(const XpbdSettings& s) {
    if (!std::isfinite(s.dt) || s.dt <= 0 || s.dt > 0.1) return "dt must be in (0, 0.1] s";
    if (s.substeps < 1 || s.substeps > 1000) return "substeps must be in [1, 1000]";
    if (s.iterations < 1 || s.iterations > 1000) return "iterations must be in [1, 1000]";
    if (!std::isfinite(s.damping) || s.damping < 0 || s.damping > 1000) return "damping must be in [0, 1000] 1/s";
    if (!s.gravity.allFinite() || s.gravity.norm() > 1000) return "gravity must be finite and at most 1000 m/s^2";
    if (!std::isfinite(s.maxSpeed) || s.maxSpeed <= 0) return "max_speed must be positive";
    return {};
}

std::unique_ptr<XpbdSolver> XpbdSolver::create(const TetMesh& rest, const Material& material,
                                               const std::vector<int32_t>& fixedNodes,
                                               const XpbdSettings& settings) {
    const std::string where = "sim::XpbdSolver::create(): ";
    if (auto why = validate(material); !why.empty()) throw std::invalid_argument(where + why);
    if (auto why = validate(settings); !why.empty()) throw std::invalid_argument(where + why);
    std::unique_ptr<XpbdSolver> s(new XpbdSolver());
    s->m_settings = settings;
    s->m_tets = rest.tets();
    s->m_rest = rest.positions();
    const size_t nv = s->m_rest.size();
    s->m_mass.assign(nv, 0.0);
    s->m_dmInv.resize(s->m_tets.size());
    s->m_restVolume.resize(s->m_tets.size());
    for (size_t t = 0; t < s->m_tets.size(); ++t) {
        const Tet& e = s->m_tets[t];
        Eigen::Matrix3d dm;
        for (int k = 0; k < 3; ++k) dm.col(k) = s->m_rest[e[k + 1]] - s->m_rest[e[0]];
        const double vol = dm.determinant() / 6.0;
        if (!(vol > 0))
            throw std::invalid_argument(where + "tet " + std::to_string(t) + " has non-positive rest volume " +
                                        std::to_string(vol) + " m^3");
        s->m_dmInv[t] = dm.inverse();
        s->m_restVolume[t] = vol;
        for (int k = 0; k < 4; ++k) s->m_mass[e[k]] += material.density * vol / 4.0;
    }
    s->m_invMass.resize(nv);
    for (size_t v = 0; v < nv; ++v) s->m_invMass[v] = s->m_mass[v] > 0 ? 1.0 / s->m_mass[v] : 0.0;
    for (int32_t f : fixedNodes) {
        if (f < 0 || static_cast<size_t>(f) >= nv)
            throw std::invalid_argument(where + "fixed node " + std::to_string(f) + " is out of range (mesh has " +
                                        std::to_string(nv) + " vertices)");
        s->m_invMass[f] = 0.0;
    }
    bool anyFree = false;
    for (double w : s->m_invMass) anyFree |= w > 0;
    if (!anyFree) throw std::invalid_argument(where + "body has no free node");
    s->m_mu = material.mu();
    s->m_lambda = material.lambda();
    s->m_gamma = 1.0 + s->m_mu / s->m_lambda;
    s->m_x = s->m_rest;
    s->m_v.assign(nv, Vec3::Zero());
    s->m_multipliers.assign(2 * s->m_tets.size(), 0.0);
    return s;
}

void XpbdSolver::solveTet(size_t t, double h2inv) {
    const Tet& e = m_tets[t];
    const double w[4] = {m_invMass[e[0]], m_invMass[e[1]], m_invMass[e[2]], m_invMass[e[3]]};
    const Eigen::Matrix3d& dmInv = m_dmInv[t];
    const double vol = m_restVolume[t];
    Eigen::Matrix3d ds;
    for (int k = 0; k < 3; ++k) ds.col(k) = m_x[e[k + 1]] - m_x[e[0]];
    const Eigen::Matrix3d F = ds * dmInv;
    // Deviatoric C_D = |F|_F and hydrostatic C_H = det F - gamma, solved together as one 2x2
    // block: the rest state balances only when both multipliers are found at once.
    const double cD = std::sqrt(F.squaredNorm());
    if (cD < 1e-12) return;
    const double cH = F.determinant() - m_gamma;
    Eigen::Matrix3d dH;
    dH.col(0) = F.col(1).cross(F.col(2));
    dH.col(1) = F.col(2).cross(F.col(0));
    dH.col(2) = F.col(0).cross(F.col(1));
    // dC/dx_i for i = 1..3 are the columns of dC/dF * Dm^-T; dC/dx_0 is minus their sum.
    const Eigen::Matrix3d gD = (F / cD) * dmInv.transpose();
    const Eigen::Matrix3d gH = dH * dmInv.transpose();
    const Vec3 gD0 = -gD.rowwise().sum();
    const Vec3 gH0 = -gH.rowwise().sum();
    double aDD = w[0] * gD0.squaredNorm(), aHH = w[0] * gH0.squaredNorm(), aDH = w[0] * gD0.dot(gH0);
    for (int k = 0; k < 3; ++k) {
        aDD += w[k + 1] * gD.col(k).squaredNorm();
        aHH += w[k + 1] * gH.col(k).squaredNorm();
        aDH += w[k + 1] * gD.col(k).dot(gH.col(k));
    }
    const double tD = h2inv / (m_mu * vol), tH = h2inv / (m_lambda * vol); // compliance / h^2
    double& lD = m_multipliers[2 * t];
    double& lH = m_multipliers[2 * t + 1];
    aDD += tD;
    aHH += tH;
    const double rD = -cD - tD * lD, rH = -cH - tH * lH;
    const double det = aDD * aHH - aDH * aDH;
    if (!(det > 0) || !std::isfinite(det)) return;
    const double dD = (aHH * rD - aDH * rH) / det;
    const double dHl = (aDD * rH - aDH * rD) / det;
    lD += dD;
    lH += dHl;
    m_x[e[0]] += w[0] * (dD * gD0 + dHl * gH0);
    for (int k = 0; k < 3; ++k) m_x[e[k + 1]] += w[k + 1] * (dD * gD.col(k) + dHl * gH.col(k));
}

StepStats XpbdSolver::step() {
    StepStats st;
    const int n = m_settings.substeps;
    const double h = m_settings.dt / n;
    const double h2inv = 1.0 / (h * h);
    const double decay = std::exp(-m_settings.damping * h);
    const double vmax = m_settings.maxSpeed;
    m_frameStart = m_x;
    const std::vector<Vec3> v0 = m_v;
    for (int s = 0; s < n; ++s) {
        m_prev = m_x;
        std::fill(m_multipliers.begin(), m_multipliers.end(), 0.0);
        for (size_t v = 0; v < m_x.size(); ++v) {
            if (m_invMass[v] == 0) continue;
            m_v[v] += h * m_settings.gravity;
            m_x[v] += h * m_v[v];
        }
        for (int it = 0; it < m_settings.iterations; ++it)
            for (size_t t = 0; t < m_tets.size(); ++t) solveTet(t, h2inv);
        for (size_t v = 0; v < m_x.size(); ++v) {
            if (m_invMass[v] == 0) {
                m_v[v].setZero();
                continue;
            }
            Vec3 vel = (m_x[v] - m_prev[v]) / h;
            const double speed = vel.norm();
            if (speed > vmax) {
                vel *= vmax / speed;
                m_x[v] = m_prev[v] + h * vel;
                ++st.speedClamps;
            }
            m_v[v] = decay * vel;
        }
    }
    st.substeps = n;
    st.iterations = m_settings.iterations;
    for (size_t v = 0; v < m_x.size(); ++v) {
        if (!m_x[v].allFinite() || !m_v[v].allFinite()) {
            st.finite = false;
            break;
        }
        st.maxDisplacement = std::max(st.maxDisplacement, (m_x[v] - m_frameStart[v]).norm());
    }
    if (!st.finite) {
        m_x = m_frameStart;
        m_v = v0;
        st.maxDisplacement = 0;
    }
    return st;
}

double XpbdSolver::elasticEnergy() const {
    double sum = 0;
    for (size_t t = 0; t < m_tets.size(); ++t) {
        const Tet& e = m_tets[t];
        Eigen::Matrix3d ds;
        for (int k = 0; k < 3; ++k) ds.col(k) = m_x[e[k + 1]] - m_x[e[0]];
        const Eigen::Matrix3d F = ds * m_dmInv[t];
        const double J = F.determinant();
        const double psi = 0.5 * m_mu * (F.squaredNorm() - 3.0) + 0.5 * m_lambda * (J - m_gamma) * (J - m_gamma) -
                           0.5 * m_mu * m_mu / m_lambda;
        sum += m_restVolume[t] * psi;
    }
    return sum;
}

double XpbdSolver::kineticEnergy() const {
    double sum = 0;
    for (size_t v = 0; v < m_x.size(); ++v) sum += 0.5 * m_mass[v] * m_v[v].squaredNorm();
    return sum;
}

double XpbdSolver::potentialEnergy() const {
    double sum = 0;
    for (size_t v = 0; v < m_x.size(); ++v) sum -= m_mass[v] * m_settings.gravity.dot(m_x[v] - m_rest[v]);
    return sum;
}

double XpbdSolver::totalMass() const {
    double m = 0;
    for (double x : m_mass) m += x;
    return m;
}

} // namespace viscera::sim
