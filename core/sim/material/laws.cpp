#include "sim/material/laws.hpp"

#include "sim/util/error.hpp"
#include "sim/util/format.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>

#include <cmath>
#include <stdexcept>

namespace viscera::sim {

namespace {

void checkLame(const char* where, double mu, double lambda) {
    if (!(mu > 0) || !std::isfinite(mu) || !(lambda >= 0) || !std::isfinite(lambda))
        throw std::invalid_argument(std::string(where) + ": mu " + formatNumber(mu, 12) + " and lambda " +
                                    formatNumber(lambda, 12) + " must be finite with mu > 0, lambda >= 0");
}

/// ∂J/∂F = cof(F), columns as cross products of the other two columns of F.
Mat3 cofactor(const Mat3& F) {
    Mat3 c;
    c.col(0) = F.col(1).cross(F.col(2));
    c.col(1) = F.col(2).cross(F.col(0));
    c.col(2) = F.col(0).cross(F.col(1));
    return c;
}

constexpr const char* kLawNames = "linear, st_venant_kirchhoff, corotated, neo_hookean";

} // namespace

// --- linear -----------------------------------------------------------------------------------

LinearElasticDensity::LinearElasticDensity(double mu, double lambda) : m_mu(mu), m_lambda(lambda) {
    checkLame("sim::LinearElasticDensity()", mu, lambda);
}

double LinearElasticDensity::psi(const Mat3& F) const {
    const Mat3 eps = 0.5 * (F + F.transpose()) - Mat3::Identity();
    const double tr = eps.trace();
    return m_mu * eps.squaredNorm() + 0.5 * m_lambda * tr * tr;
}

Mat3 LinearElasticDensity::stress(const Mat3& F) const {
    const Mat3 eps = 0.5 * (F + F.transpose()) - Mat3::Identity();
    return 2.0 * m_mu * eps + m_lambda * eps.trace() * Mat3::Identity();
}

double LinearElasticDensity::psiAndStress(const Mat3& F, Mat3& P) const {
    const Mat3 eps = 0.5 * (F + F.transpose()) - Mat3::Identity();
    const double tr = eps.trace();
    P = 2.0 * m_mu * eps + m_lambda * tr * Mat3::Identity();
    return m_mu * eps.squaredNorm() + 0.5 * m_lambda * tr * tr;
}

// --- St. Venant–Kirchhoff ---------------------------------------------------------------------

StVenantKirchhoffDensity::StVenantKirchhoffDensity(double mu, double lambda) : m_mu(mu), m_lambda(lambda) {
    checkLame("sim::StVenantKirchhoffDensity()", mu, lambda);
}

double StVenantKirchhoffDensity::psi(const Mat3& F) const {
    const Mat3 E = 0.5 * (F.transpose() * F - Mat3::Identity());
    const double tr = E.trace();
    return m_mu * E.squaredNorm() + 0.5 * m_lambda * tr * tr;
}

Mat3 StVenantKirchhoffDensity::stress(const Mat3& F) const {
    const Mat3 E = 0.5 * (F.transpose() * F - Mat3::Identity());
    return F * (2.0 * m_mu * E + m_lambda * E.trace() * Mat3::Identity());
}

double StVenantKirchhoffDensity::psiAndStress(const Mat3& F, Mat3& P) const {
    const Mat3 E = 0.5 * (F.transpose() * F - Mat3::Identity());
    const double tr = E.trace();
    P = F * (2.0 * m_mu * E + m_lambda * tr * Mat3::Identity());
    return m_mu * E.squaredNorm() + 0.5 * m_lambda * tr * tr;
}

// --- corotated linear -------------------------------------------------------------------------

CorotatedLinearDensity::CorotatedLinearDensity(double mu, double lambda) : m_mu(mu), m_lambda(lambda) {
    checkLame("sim::CorotatedLinearDensity()", mu, lambda);
}

double CorotatedLinearDensity::psi(const Mat3& F) const {
    const Eigen::Vector3d s = signedSvd(F).sigma;
    const double tr = s.sum() - 3.0;
    return m_mu * (s.array() - 1.0).square().sum() + 0.5 * m_lambda * tr * tr;
}

Mat3 CorotatedLinearDensity::stress(const Mat3& F) const {
    const SignedSvd svd = signedSvd(F);
    const Mat3 R = svd.U * svd.V.transpose();
    return 2.0 * m_mu * (F - R) + m_lambda * (svd.sigma.sum() - 3.0) * R;
}

double CorotatedLinearDensity::psiAndStress(const Mat3& F, Mat3& P) const {
    const SignedSvd svd = signedSvd(F);
    const Mat3 R = svd.U * svd.V.transpose();
    P = 2.0 * m_mu * (F - R) + m_lambda * (svd.sigma.sum() - 3.0) * R;
    const Eigen::Vector3d& s = svd.sigma;
    const double tr = s.sum() - 3.0;
    return m_mu * (s.array() - 1.0).square().sum() + 0.5 * m_lambda * tr * tr;
}

// --- Neo-Hookean ------------------------------------------------------------------------------

NeoHookeanDensity::NeoHookeanDensity(double mu, double lambda, double jMin) : m_mu(mu), m_lambda(lambda), m_jMin(jMin) {
    checkLame("sim::NeoHookeanDensity()", mu, lambda);
    if (!(jMin > 0 && jMin < 1))
        throw std::invalid_argument("sim::NeoHookeanDensity(): jMin " + formatNumber(jMin, 12) + " must be in (0, 1)");
}

void NeoHookeanDensity::phi(double J, double& value, double& slope) const {
    if (J >= m_jMin) {
        const double l = std::log(J);
        value = -m_mu * l + 0.5 * m_lambda * l * l;
        slope = (m_lambda * l - m_mu) / J;
        return;
    }
    const double l = std::log(m_jMin);
    const double p0 = -m_mu * l + 0.5 * m_lambda * l * l;
    const double p1 = (m_lambda * l - m_mu) / m_jMin;
    const double p2 = (m_mu + m_lambda * (1.0 - l)) / (m_jMin * m_jMin);
    const double d = J - m_jMin;
    value = p0 + d * (p1 + 0.5 * p2 * d);
    slope = p1 + p2 * d;
}

double NeoHookeanDensity::psi(const Mat3& F) const {
    double value, slope;
    phi(F.determinant(), value, slope);
    return 0.5 * m_mu * (F.squaredNorm() - 3.0) + value;
}

Mat3 NeoHookeanDensity::stress(const Mat3& F) const {
    double value, slope;
    phi(F.determinant(), value, slope);
    return m_mu * F + slope * cofactor(F);
}

double NeoHookeanDensity::psiAndStress(const Mat3& F, Mat3& P) const {
    double value, slope;
    phi(F.determinant(), value, slope);
    P = m_mu * F + slope * cofactor(F);
    return 0.5 * m_mu * (F.squaredNorm() - 3.0) + value;
}

// --- factories --------------------------------------------------------------------------------

std::unique_ptr<EnergyDensity> makeEnergyDensity(const std::string& name, double mu, double lambda) {
    if (name == "linear") return std::make_unique<LinearElasticDensity>(mu, lambda);
    if (name == "st_venant_kirchhoff") return std::make_unique<StVenantKirchhoffDensity>(mu, lambda);
    if (name == "corotated") return std::make_unique<CorotatedLinearDensity>(mu, lambda);
    if (name == "neo_hookean") return std::make_unique<NeoHookeanDensity>(mu, lambda);
    throw InputError("unknown energy density '" + name + "' (supported: " + kLawNames + ")");
}

ValanisLandelCurves stVenantKirchhoffCurves(double mu, double lambda) {
    checkLame("sim::stVenantKirchhoffCurves()", mu, lambda);
    ValanisLandelCurves curves;
    const double a = mu + 0.5 * lambda;
    curves.fPrime = MonotoneCurve::fit(
        "f'", [a, lambda](double x) { return a * (x * x * x - x) - lambda * x; },
        {.xmin = -4.0, .xmax = 4.0, .count = 17, .spacing = CurveSpacing::Uniform, .shape = CurveShape::Unconstrained});
    if (lambda > 0)
        curves.gPrime = MonotoneCurve::fit("g'", [lambda](double y) { return 0.5 * lambda * y; },
                                           {.xmin = -16.0,
                                            .xmax = 16.0,
                                            .count = 17,
                                            .spacing = CurveSpacing::Uniform,
                                            .shape = CurveShape::StrictlyIncreasing});
    return curves;
}

ValanisLandelCurves corotatedCurves(double mu, double lambda) {
    checkLame("sim::corotatedCurves()", mu, lambda);
    ValanisLandelCurves curves;
    curves.fPrime =
        MonotoneCurve::fit("f'", [mu, lambda](double x) { return (2.0 * mu + lambda) * (x - 1.0) - 2.0 * lambda; },
                           {.xmin = -4.0,
                            .xmax = 4.0,
                            .count = 9,
                            .spacing = CurveSpacing::Uniform,
                            .shape = CurveShape::StrictlyIncreasing});
    if (lambda > 0)
        curves.gPrime = MonotoneCurve::fit("g'", [lambda](double) { return lambda; },
                                           {.xmin = -16.0,
                                            .xmax = 16.0,
                                            .count = 9,
                                            .spacing = CurveSpacing::Uniform,
                                            .shape = CurveShape::Unconstrained});
    return curves;
}

ValanisLandelCurves valanisLandelCurves(const std::string& name, double mu, double lambda) {
    if (name == "st_venant_kirchhoff") return stVenantKirchhoffCurves(mu, lambda);
    if (name == "corotated") return corotatedCurves(mu, lambda);
    if (name == "neo_hookean") return neoHookeanCurves(mu, lambda);
    if (name == "linear")
        throw InputError("energy density 'linear' has no Valanis-Landel form (it is not "
                         "rotation invariant)");
    throw InputError("unknown energy density '" + name + "' (supported: " + kLawNames + ")");
}

} // namespace viscera::sim
