#pragma once
/// Shared fixtures for the material tests: parameter sweeps, deformation-gradient samples and
/// central finite differences.
#include "sim/material/laws.hpp"
#include "sim/material/valanis_landel.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/SVD>

#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <random>
#include <string>
#include <vector>

namespace viscera::sim::testing {

/// The message of what `fn` throws, or "(no exception)".
inline std::string messageOf(const std::function<void()>& fn) {
    try {
        fn();
    } catch (const std::exception& e) {
        return e.what();
    }
    return "(no exception)";
}

struct Lame {
    double youngs, poisson, mu, lambda;
};

/// E in {1 kPa, 30 kPa, 1 MPa} × ν in {0.3, 0.45, 0.49, 0.499}.
inline std::vector<Lame> lameSweep() {
    std::vector<Lame> out;
    for (double E : {1e3, 3e4, 1e6})
        for (double nu : {0.3, 0.45, 0.49, 0.499})
            out.push_back({E, nu, E / (2.0 * (1.0 + nu)), E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))});
    return out;
}

inline Mat3 randomRotation(std::mt19937& rng) {
    std::normal_distribution<double> n(0.0, 1.0);
    Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
    return q.normalized().toRotationMatrix();
}

struct FSample {
    std::string kind;
    Mat3 F;
};

/// Singular values of F well separated (relative gap ≥ 10 %), so that the signed SVD is smooth
/// around F and finite differences are meaningful (no tie |σ3| = σ2 under inversion).
inline bool wellSeparated(const Mat3& F) {
    const Eigen::Vector3d s = Eigen::JacobiSVD<Mat3>(F).singularValues();
    return s(0) - s(1) > 0.1 * s(0) && s(1) - s(2) > 0.1 * s(1) && s(2) > 0.05;
}

/// Random deformation gradients: stretched, compressed, sheared and inverted, `perKind` each.
inline std::vector<FSample> sampleDeformations(int perKind, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<FSample> out;
    const auto diagStretch = [&](double lo, double hi) {
        Mat3 F;
        do {
            const Eigen::Vector3d s(lo + (hi - lo) * u(rng), lo + (hi - lo) * u(rng), lo + (hi - lo) * u(rng));
            F = randomRotation(rng) * s.asDiagonal() * randomRotation(rng).transpose();
        } while (!wellSeparated(F));
        return F;
    };
    for (int i = 0; i < perKind; ++i)
        out.push_back({"stretched", diagStretch(1.05, 2.5)});
    for (int i = 0; i < perKind; ++i)
        out.push_back({"compressed", diagStretch(0.35, 0.95)});
    for (int i = 0; i < perKind; ++i) {
        Mat3 F;
        do {
            F = Mat3::Identity();
            for (int r = 0; r < 3; ++r)
                for (int c = 0; c < 3; ++c)
                    if (r != c) F(r, c) = 1.2 * (u(rng) - 0.5);
            F = randomRotation(rng) * F;
        } while (!wellSeparated(F) || F.determinant() <= 0);
        out.push_back({"sheared", F});
    }
    for (int i = 0; i < perKind; ++i) {
        Mat3 F;
        do {
            const Eigen::Vector3d s(0.6 + 1.4 * u(rng), 0.6 + 1.4 * u(rng), -(0.1 + 0.4 * u(rng)));
            F = randomRotation(rng) * s.asDiagonal() * randomRotation(rng).transpose();
        } while (!wellSeparated(F));
        out.push_back({"inverted", F});
    }
    return out;
}

/// Fourth-order central differences of a scalar function of F,
///     g = (−ψ(F + 2hE) + 8ψ(F + hE) − 8ψ(F − hE) + ψ(F − 2hE)) / 12h,
/// step h = 1e-5 · max(1, max|F_ij|): truncation O(h⁴) is negligible and the larger step keeps
/// the rounding of energies that cancel large terms (λ ≫ μ) below 1e-8 relative.
inline Mat3 centralDifference(const std::function<double(const Mat3&)>& fn, const Mat3& F) {
    const double h = 1e-5 * std::max(1.0, F.cwiseAbs().maxCoeff());
    Mat3 g;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) {
            const auto at = [&](double t) {
                Mat3 G = F;
                G(r, c) += t * h;
                return fn(G);
            };
            g(r, c) = (-at(2) + 8.0 * at(1) - 8.0 * at(-1) + at(-2)) / (12.0 * h);
        }
    return g;
}

/// "1.234e-09": figures recorded with RecordProperty (XML output only; tests never print).
inline std::string sci(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3e", v);
    return buf;
}

/// ‖G_fd − G‖_F / ‖G‖_F (with a floor of 1e-12 · scale in the denominator).
inline double relativeGradientError(const Mat3& analytic, const Mat3& fd, double scale) {
    return (fd - analytic).norm() / std::max(analytic.norm(), 1e-12 * scale);
}

/// A tissue-like authored material with all three curves present and a balanced rest state:
/// f′(1) + 2g′(1) + h′(1) = 200 + 2·100 − 400 = 0.
inline ValanisLandelCurves authoredTissueCurves() {
    ValanisLandelCurves c;
    c.fPrime = MonotoneCurve("f'", {{0.2, -3000}, {0.6, -600}, {1.0, 200}, {1.3, 1500}, {2.0, 12000}});
    c.gPrime = MonotoneCurve("g'", {{0.1, -500}, {1.0, 100}, {3.0, 1500}});
    c.hPrime = MonotoneCurve("h'", {{0.05, -60000}, {0.5, -6000}, {1.0, -400}, {2.0, 2000}, {8.0, 6000}});
    return c;
}

struct NamedDensity {
    std::string label;
    std::shared_ptr<const EnergyDensity> density;
    bool rotationInvariant = true;
};

/// Every law of laws.hpp, the Valanis–Landel forms of those that have one, and (independent of
/// μ, λ) the authored tissue material.
inline std::vector<NamedDensity> allDensities(double mu, double lambda) {
    std::vector<NamedDensity> out;
    out.push_back({"linear", std::make_shared<LinearElasticDensity>(mu, lambda), false});
    out.push_back({"st_venant_kirchhoff", std::make_shared<StVenantKirchhoffDensity>(mu, lambda)});
    out.push_back({"corotated", std::make_shared<CorotatedLinearDensity>(mu, lambda)});
    out.push_back({"neo_hookean", std::make_shared<NeoHookeanDensity>(mu, lambda)});
    for (const char* law : {"st_venant_kirchhoff", "corotated", "neo_hookean"})
        out.push_back({std::string("vl_") + law,
                       std::make_shared<ValanisLandelDensity>(law, valanisLandelCurves(law, mu, lambda))});
    out.push_back({"vl_authored_tissue", std::make_shared<ValanisLandelDensity>("tissue", authoredTissueCurves())});
    return out;
}

} // namespace viscera::sim::testing
