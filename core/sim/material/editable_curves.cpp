#include "sim/material/editable_curves.hpp"

#include "sim/material/material.hpp"
#include "sim/util/error.hpp"
#include "sim/util/format.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>

namespace viscera::sim {

namespace {

/// Control points y = fn(x) at the given abscissae; StrictlyIncreasing when the values increase
/// strictly (and `allowIncreasing`), else Unconstrained.
MonotoneCurve sampled(std::string name, const std::vector<double>& xs, const std::function<double(double)>& fn,
                      bool allowIncreasing = true) {
    std::vector<CurvePoint> points;
    points.reserve(xs.size());
    bool increasing = allowIncreasing;
    for (double x : xs) {
        points.push_back({x, fn(x)});
        if (points.size() > 1 && !(points.back().y > points[points.size() - 2].y)) increasing = false;
    }
    return MonotoneCurve(std::move(name), std::move(points),
                         increasing ? CurveShape::StrictlyIncreasing : CurveShape::Unconstrained);
}

double valueAt(const std::optional<MonotoneCurve>& c, double x) {
    return c ? c->value(x) : 0.0;
}
double slopeAt(const std::optional<MonotoneCurve>& c, double x) {
    return c ? c->derivative(x) : 0.0;
}
double restPrimitive(const std::optional<MonotoneCurve>& c) {
    return c ? c->integralFromRest(1.0) : 0.0;
}

} // namespace

const std::vector<double>& editableStretchPoints() {
    static const std::vector<double> points{0.3, 0.5, 0.7, 0.85, 1.0, 1.15, 1.3, 1.5, 1.75, 2.0, 2.5, 3.0};
    return points;
}

const std::vector<double>& editableVolumePoints() {
    static const std::vector<double> points{0.3, 0.5, 0.7, 0.85, 0.95, 1.0, 1.05, 1.15, 1.3, 1.5, 2.0, 2.5};
    return points;
}

ValanisLandelCurves editableCurves(const std::string& law, double youngsModulus, double poissonRatio) {
    Material m;
    m.youngsModulus = youngsModulus;
    m.poissonRatio = poissonRatio;
    if (const std::string rule = validate(m); !rule.empty())
        throw std::invalid_argument("sim::editableCurves(): " + rule);
    const double mu = m.mu(), lambda = m.lambda();
    ValanisLandelCurves c;
    if (law == "neo_hookean") {
        c.fPrime = sampled("f'", editableStretchPoints(), [mu](double x) { return mu * x; });
        c.hPrime =
            sampled("h'", editableVolumePoints(), [mu, lambda](double J) { return (lambda * std::log(J) - mu) / J; });
    } else if (law == "st_venant_kirchhoff") {
        const double a = mu + 0.5 * lambda;
        c.fPrime = sampled(
            "f'", editableStretchPoints(), [a, lambda](double x) { return a * (x * x * x - x) - lambda * x; }, false);
        if (lambda > 0)
            c.gPrime = sampled("g'", editableStretchPoints(), [lambda](double y) { return 0.5 * lambda * y; });
    } else if (law == "corotated") {
        c.fPrime = sampled("f'", editableStretchPoints(),
                           [mu, lambda](double x) { return (2.0 * mu + lambda) * (x - 1.0) - 2.0 * lambda; });
        if (lambda > 0) c.gPrime = sampled("g'", editableStretchPoints(), [lambda](double) { return lambda; });
    } else {
        throw InputError("unknown editable curve preset '" + law +
                         "' (supported: neo_hookean, st_venant_kirchhoff, corotated)");
    }
    return c;
}

SmallStrainConstants smallStrainConstants(const ValanisLandelCurves& curves) {
    const ValanisLandelDensity density("curves", curves);
    SmallStrainConstants out;
    out.shearModulus = density.shearModulus();
    out.lameLambda = density.lameLambda();
    const double mu = out.shearModulus, lambda = out.lameLambda;
    const double bulk = lambda + 2.0 * mu / 3.0;
    if (!(bulk > 0))
        throw InputError("material 'curves': small-strain bulk modulus lambda + 2 mu/3 = " + formatNumber(bulk, 12) +
                         " Pa is not positive (mu=" + formatNumber(mu, 12) + " Pa, lambda=" + formatNumber(lambda, 12) +
                         " Pa)");
    out.youngsModulus = mu * (3.0 * lambda + 2.0 * mu) / (lambda + mu);
    out.poissonRatio = lambda / (2.0 * (lambda + mu));
    return out;
}

RestNormalization restNormalization(const ValanisLandelCurves& curves) {
    const auto& f = curves.fPrime;
    const auto& g = curves.gPrime;
    const auto& h = curves.hPrime;
    RestNormalization out;
    out.restEnergy = 3.0 * restPrimitive(f) + 3.0 * restPrimitive(g) + restPrimitive(h);
    const double f1 = valueAt(f, 1.0), g1 = valueAt(g, 1.0), h1 = valueAt(h, 1.0);
    out.restStress = f1 + 2.0 * g1 + h1;
    const double stiffness = slopeAt(f, 1.0) + 2.0 * slopeAt(g, 1.0) + slopeAt(h, 1.0);
    const double scale = std::max({std::abs(f1), std::abs(2.0 * g1), std::abs(h1), std::abs(stiffness)});
    out.restStressTolerance = ValanisLandelDensity::kRestStressTolerance * scale;
    out.balanced = std::abs(out.restStress) <= out.restStressTolerance;
    return out;
}

} // namespace viscera::sim
