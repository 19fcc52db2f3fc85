#include "sim/material/valanis_landel.hpp"

#include "sim/util/error.hpp"

#include <Eigen/LU>
#include <Eigen/SVD>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace viscera::sim {

namespace {

std::string num(double v) {
    if (std::isnan(v)) return "nan"; // not "-nan": messages are compared verbatim
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.12g", v);
    return buf;
}

double curveValue(const std::optional<MonotoneCurve>& c, double x) {
    return c ? c->value(x) : 0.0;
}
double curveSlope(const std::optional<MonotoneCurve>& c, double x) {
    return c ? c->derivative(x) : 0.0;
}
/// ∫₁ˣ c (the rest-normalized energy term).
double curveEnergy(const std::optional<MonotoneCurve>& c, double x) {
    return c ? c->integral(1.0, x) : 0.0;
}

} // namespace

SignedSvd signedSvd(const Mat3& F) {
    Eigen::JacobiSVD<Mat3> svd(F, Eigen::ComputeFullU | Eigen::ComputeFullV);
    SignedSvd out{svd.matrixU(), svd.singularValues(), svd.matrixV()};
    // Singular values come sorted decreasingly; a reflection in U or V moves to σ3.
    if (out.U.determinant() < 0) {
        out.U.col(2) *= -1.0;
        out.sigma(2) *= -1.0;
    }
    if (out.V.determinant() < 0) {
        out.V.col(2) *= -1.0;
        out.sigma(2) *= -1.0;
    }
    return out;
}

ValanisLandelDensity::ValanisLandelDensity(std::string materialName, ValanisLandelCurves curves)
    : m_materialName(std::move(materialName)), m_curves(std::move(curves)) {
    const std::string where = "material '" + m_materialName + "'";
    for (auto* c : {&m_curves.fPrime, &m_curves.gPrime, &m_curves.hPrime}) {
        if (!*c) continue;
        (*c)->setContext(where);
        (*c)->validate();
    }
    const auto& f = m_curves.fPrime;
    const auto& g = m_curves.gPrime;
    const auto& h = m_curves.hPrime;
    const double f1 = curveValue(f, 1.0), g1 = curveValue(g, 1.0), h1 = curveValue(h, 1.0);
    const double f2 = curveSlope(f, 1.0), g2 = curveSlope(g, 1.0), h2 = curveSlope(h, 1.0);
    m_restStiffness = f2 + 2.0 * g2 + h2;
    m_shearModulus = 0.5 * (f2 + g2 - g1 - h1);

    const auto describe = [&](const char* label, const std::optional<MonotoneCurve>& c, double v) {
        return std::string(label) + (c ? "(1)=" + num(v) : " absent");
    };
    const std::string values =
        describe("f'", f, f1) + ", " + describe("g'", g, g1) + ", " + describe("h'", h, h1);
    const double rest = f1 + 2.0 * g1 + h1;
    const double scale =
        std::max({std::abs(f1), std::abs(2.0 * g1), std::abs(h1), std::abs(m_restStiffness)});
    if (!(std::abs(rest) <= kRestStressTolerance * scale))
        throw InputError(where + ": stress at rest f'(1) + 2 g'(1) + h'(1) = " + num(rest) +
                         " Pa is not zero (" + values + ")");
    if (!(m_restStiffness > 0))
        throw InputError(where + ": stiffness at rest f''(1) + 2 g''(1) + h''(1) = " +
                         num(m_restStiffness) + " Pa is not positive (" + values + ")");
    if (!(m_shearModulus > 0))
        throw InputError(where + ": shear modulus at rest (f''(1) + g''(1) - g'(1) - h'(1))/2 = " +
                         num(m_shearModulus) + " Pa is not positive (" + values + ")");
}

double ValanisLandelDensity::psiPrincipal(const Eigen::Vector3d& s) const {
    const auto& c = m_curves;
    double e = 0;
    if (c.fPrime)
        e +=
            curveEnergy(c.fPrime, s(0)) + curveEnergy(c.fPrime, s(1)) + curveEnergy(c.fPrime, s(2));
    if (c.gPrime)
        e += curveEnergy(c.gPrime, s(0) * s(1)) + curveEnergy(c.gPrime, s(1) * s(2)) +
             curveEnergy(c.gPrime, s(0) * s(2));
    if (c.hPrime) e += curveEnergy(c.hPrime, s(0) * s(1) * s(2));
    return e;
}

Eigen::Vector3d ValanisLandelDensity::stressPrincipal(const Eigen::Vector3d& s) const {
    const auto& c = m_curves;
    Eigen::Vector3d d = Eigen::Vector3d::Zero();
    if (c.fPrime)
        for (int i = 0; i < 3; ++i)
            d(i) += c.fPrime->value(s(i));
    if (c.gPrime) {
        const double g01 = c.gPrime->value(s(0) * s(1));
        const double g12 = c.gPrime->value(s(1) * s(2));
        const double g02 = c.gPrime->value(s(0) * s(2));
        d(0) += s(1) * g01 + s(2) * g02;
        d(1) += s(0) * g01 + s(2) * g12;
        d(2) += s(0) * g02 + s(1) * g12;
    }
    if (c.hPrime) {
        const double hJ = c.hPrime->value(s(0) * s(1) * s(2));
        d(0) += s(1) * s(2) * hJ;
        d(1) += s(0) * s(2) * hJ;
        d(2) += s(0) * s(1) * hJ;
    }
    return d;
}

double ValanisLandelDensity::psi(const Mat3& F) const {
    return psiPrincipal(signedSvd(F).sigma);
}

Mat3 ValanisLandelDensity::stress(const Mat3& F) const {
    const SignedSvd svd = signedSvd(F);
    return svd.U * stressPrincipal(svd.sigma).asDiagonal() * svd.V.transpose();
}

ValanisLandelCurves neoHookeanCurves(double mu, double lambda,
                                     const NeoHookeanCurveOptions& options) {
    if (!(mu > 0) || !std::isfinite(mu) || !(lambda >= 0) || !std::isfinite(lambda))
        throw std::invalid_argument("sim::neoHookeanCurves(): mu " + num(mu) + " and lambda " +
                                    num(lambda) + " must be finite with mu > 0, lambda >= 0");
    ValanisLandelCurves curves;
    curves.fPrime = MonotoneCurve::fit("f'", [mu](double x) { return mu * x; },
                                       {.xmin = options.stretchMin,
                                        .xmax = options.stretchMax,
                                        .count = options.stretchCount,
                                        .spacing = CurveSpacing::Geometric,
                                        .shape = CurveShape::StrictlyIncreasing});
    // h′ peaks at J = exp(1 + μ/λ) (h″ = (μ + λ(1 − log J))/J²).
    const double peak =
        lambda > 0 ? std::exp(1.0 + mu / lambda) : std::numeric_limits<double>::infinity();
    curves.hPrime =
        MonotoneCurve::fit("h'", [mu, lambda](double J) { return (lambda * std::log(J) - mu) / J; },
                           {.xmin = options.volumeMin,
                            .xmax = options.volumeMax,
                            .count = options.volumeCount,
                            .spacing = CurveSpacing::Geometric,
                            .shape = options.volumeMax < peak ? CurveShape::StrictlyIncreasing
                                                              : CurveShape::Unconstrained});
    return curves;
}

} // namespace viscera::sim
