#pragma once
// Shared fixtures for the sim/xpbd tests.
#include "sim/material/constraint_model.hpp"
#include "sim/material/material.hpp"
#include "sim/mesh/generators.hpp"

#include <Eigen/Dense>

#include <cmath>
#include <functional>
#include <memory>
#include <random>
#include <vector>

namespace viscera::sim::testing {

struct Cantilever {
    std::unique_ptr<TetMesh> mesh;
    std::vector<int32_t> fixed;
};

/// 8 × 2 × 2 cm block, fixed at x = 0.
inline Cantilever cantilever(std::array<int, 3> cells = {8, 2, 2}) {
    Cantilever c;
    c.mesh = makeBoxTetMesh({Vec3::Zero(), Vec3(0.08, 0.02, 0.02), cells});
    for (int32_t v = 0; v < static_cast<int32_t>(c.mesh->vertexCount()); ++v)
        if (c.mesh->positions()[v].x() < 1e-9) c.fixed.push_back(v);
    return c;
}

inline Material tissue(double E = 20000, double nu = 0.45) {
    Material m;
    m.youngsModulus = E;
    m.poissonRatio = nu;
    return m;
}

/// Stable Neo-Hookean written as a generic model (not StableNeoHookeanModel), so that the
/// solver takes its generic path: C_D = |F|, C_H = det F − γ.
class GenericSnhModel final : public TetConstraintModel {
public:
    GenericSnhModel(double mu, double lambda) : m_mu(mu), m_lambda(lambda), m_gamma(1 + mu / lambda) {}
    std::string name() const override { return "test_generic_snh"; }
    int count() const override { return 2; }
    std::array<double, kMaxTetConstraints> compliance() const override { return {1 / m_mu, 1 / m_lambda}; }
    void evaluate(const Mat3& F, TetConstraintValues& out) const override {
        out.count = 2;
        out.C[0] = F.norm();
        out.dCdF[0] = out.C[0] > 0 ? Mat3(F / out.C[0]) : Mat3::Zero();
        out.C[1] = F.determinant() - m_gamma;
        out.dCdF[1].col(0) = F.col(1).cross(F.col(2));
        out.dCdF[1].col(1) = F.col(2).cross(F.col(0));
        out.dCdF[1].col(2) = F.col(0).cross(F.col(1));
    }
    double restStiffness() const override { return m_lambda + 2 * m_mu; }

private:
    double m_mu, m_lambda, m_gamma;
};

/// One constraint C = sqrt(2Ψ) with Ψ = μ |E|² + λ/2 tr²E (St. Venant–Kirchhoff), α = 1;
/// C = 0 and zero gradient at rest.
class OneConstraintStvkModel final : public TetConstraintModel {
public:
    OneConstraintStvkModel(double mu, double lambda) : m_mu(mu), m_lambda(lambda) {}
    std::string name() const override { return "test_sqrt_stvk"; }
    int count() const override { return 1; }
    std::array<double, kMaxTetConstraints> compliance() const override { return {1.0, 1.0}; }
    void evaluate(const Mat3& F, TetConstraintValues& out) const override {
        out.count = 1;
        const Mat3 E = 0.5 * (F.transpose() * F - Mat3::Identity());
        const double psi = m_mu * E.squaredNorm() + 0.5 * m_lambda * E.trace() * E.trace();
        if (!(psi > 1e-14 * (m_lambda + 2 * m_mu))) {
            out.C[0] = 0;
            out.dCdF[0].setZero();
            return;
        }
        const Mat3 P = F * (2 * m_mu * E + m_lambda * E.trace() * Mat3::Identity());
        out.C[0] = std::sqrt(2 * psi);
        out.dCdF[0] = P / out.C[0];
    }
    double restStiffness() const override { return m_lambda + 2 * m_mu; }

private:
    double m_mu, m_lambda;
};

/// Relative error of an analytic gradient against central differences of f, over all
/// coordinates of the points x: max |g − g_fd| / max(|g|_∞, scale).
inline double fdRelativeError(const std::function<double(const std::vector<Vec3>&)>& f, const std::vector<Vec3>& x,
                              const std::vector<Vec3>& g, double step = 1e-6, double scale = 1e-8) {
    double err = 0, norm = scale;
    for (size_t i = 0; i < x.size(); ++i)
        for (int a = 0; a < 3; ++a) {
            std::vector<Vec3> xp = x, xm = x;
            xp[i][a] += step;
            xm[i][a] -= step;
            const double fd = (f(xp) - f(xm)) / (2 * step);
            err = std::max(err, std::abs(fd - g[i][a]));
            norm = std::max(norm, std::abs(g[i][a]));
        }
    return err / norm;
}

/// A random deformation gradient near the identity (|F − I| up to `amount`), det > 0.
inline Mat3 randomF(std::mt19937& rng, double amount) {
    std::uniform_real_distribution<double> u(-amount, amount);
    Mat3 F;
    do {
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c)
                F(r, c) = (r == c ? 1.0 : 0.0) + u(rng);
    } while (F.determinant() < 0.2);
    return F;
}

} // namespace viscera::sim::testing
