#include "sim/material/material_response.hpp"

#include "sim/material/valanis_landel.hpp"
#include "sim/util/error.hpp"
#include "sim/util/format.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace viscera::sim {

namespace {

struct AxialStress {
    double p11 = 0, p22 = 0;
};

/// P11 and the free face's stress (p22: P22 uniaxial, P33 otherwise) at the load case's F: a
/// Valanis–Landel density in its principal frame (no SVD), any other through stress().
class AxialEvaluator {
public:
    explicit AxialEvaluator(const EnergyDensity& density, LoadCase c = LoadCase::Uniaxial)
        : m_density(density), m_vl(dynamic_cast<const ValanisLandelDensity*>(&density)), m_case(c) {}

    Eigen::Vector3d stretches(double lambda, double t) const {
        switch (m_case) {
        case LoadCase::Equibiaxial:
            return {lambda, lambda, t};
        case LoadCase::PlanarShear:
            return {lambda, 1.0, t};
        default:
            return {lambda, t, t};
        }
    }
    double guess(double lambda) const {
        return m_case == LoadCase::Uniaxial      ? 1.0 / std::sqrt(lambda)
               : m_case == LoadCase::Equibiaxial ? 1.0 / (lambda * lambda)
                                                 : 1.0 / lambda;
    }
    AxialStress operator()(double lambda, double t) const {
        const int free = m_case == LoadCase::Uniaxial ? 1 : 2;
        const Eigen::Vector3d s = stretches(lambda, t);
        if (m_vl) {
            const Eigen::Vector3d d = m_vl->stressPrincipal(s);
            return {d(0), d(free)};
        }
        const Mat3 P = m_density.stress(s.asDiagonal());
        return {P(0, 0), P(free, free)};
    }

private:
    const EnergyDensity& m_density;
    const ValanisLandelDensity* m_vl;
    LoadCase m_case;
};

/// The uniaxial solve with what a failure message needs.
struct Solve {
    UniaxialResponse response;
    double firstT = 1, firstP22 = 0; ///< the guess
    double lastT = 1, lastP22 = 0;   ///< where the bracket search stopped
    bool notFinite = false;
};

void checkStretch(const char* where, double stretch) {
    if (!std::isfinite(stretch) || !(stretch > 0))
        throw std::invalid_argument(std::string(where) + "stretch " + formatNumber(stretch, 12) +
                                    " must be finite and positive");
}

Solve solve(const AxialEvaluator& eval, double lambda, double guess) {
    Solve out;
    UniaxialResponse& r = out.response;
    r.stretch = lambda;
    const auto g = [&](double t) {
        ++r.evaluations;
        return eval(lambda, t);
    };
    const auto finish = [&](double t, const AxialStress& s) {
        r.lateralStretch = t;
        r.nominalStress = s.p11;
        r.lateralStress = s.p22;
        r.solved = std::isfinite(s.p11);
        if (!r.solved) {
            out.notFinite = true;
            r.lateralStretch = 1;
            r.nominalStress = r.lateralStress = 0;
        }
        return out;
    };
    const auto fail = [&](double t, double p22, bool notFinite) {
        out.lastT = t;
        out.lastP22 = std::isfinite(p22) ? p22 : 0.0;
        out.notFinite = notFinite;
        r.solved = false;
        return out;
    };

    double t = std::clamp(guess > 0 ? guess : eval.guess(lambda), kMinLateralStretch, kMaxLateralStretch);
    AxialStress st = g(t);
    out.firstT = t;
    out.firstP22 = st.p22;
    if (!std::isfinite(st.p22)) return fail(t, st.p22, true);
    if (st.p22 == 0) return finish(t, st);

    // Bracket: P22 grows with t for a stable material, so go up while P22 < 0, down while > 0,
    // by ratios 1.05, 1.05², 1.05⁴, ... (a warm guess is usually bracketed in one step).
    const bool up = st.p22 < 0;
    double ratio = 1.05;
    double a, b;
    AxialStress sa, sb;
    for (;;) {
        const double next = std::clamp(up ? t * ratio : t / ratio, kMinLateralStretch, kMaxLateralStretch);
        const AxialStress sn = g(next);
        if (!std::isfinite(sn.p22)) return fail(next, sn.p22, true);
        if (sn.p22 == 0) return finish(next, sn);
        if ((sn.p22 > 0) == up) {
            if (up) {
                a = t, sa = st, b = next, sb = sn;
            } else {
                a = next, sa = sn, b = t, sb = st;
            }
            break;
        }
        if (next == kMinLateralStretch || next == kMaxLateralStretch) return fail(next, sn.p22, false);
        t = next;
        st = sn;
        ratio = std::min(ratio * ratio, 1e3);
    }

    // rtsafe: Newton from a forward-difference slope, bisection (geometric for a wide bracket)
    // whenever the step leaves (a, b) or the residual does not halve fast enough.
    bool fromA = std::abs(sa.p22) < std::abs(sb.p22);
    double x = fromA ? a : b;
    AxialStress sx = fromA ? sa : sb;
    double dx = b - a, dxOld = dx;
    constexpr int kMaxIterations = 100;
    for (int it = 0; it < kMaxIterations; ++it) {
        const double h = 1e-7 * x;
        const AxialStress sh = g(x + h);
        const double slope = (sh.p22 - sx.p22) / h;
        const double newton = x - sx.p22 / slope;
        const bool useNewton = std::isfinite(newton) && slope > 0 && newton > a && newton < b &&
                               std::abs(2.0 * sx.p22) <= std::abs(dxOld * slope);
        dxOld = dx;
        double xn;
        if (useNewton) {
            xn = newton;
        } else {
            xn = b > 4.0 * a ? std::sqrt(a * b) : 0.5 * (a + b);
        }
        dx = xn - x;
        const AxialStress sn = g(xn);
        if (!std::isfinite(sn.p22)) return fail(xn, sn.p22, true);
        if (sn.p22 == 0) return finish(xn, sn);
        if (sn.p22 < 0)
            a = xn, sa = sn;
        else
            b = xn, sb = sn;
        x = xn;
        sx = sn;
        if (std::abs(dx) <= 1e-14 * x || b - a <= 4e-16 * x) break;
    }
    // Converged, or (after kMaxIterations, which bisection alone would not need) the best end.
    if (std::abs(sa.p22) < std::abs(sx.p22)) x = a, sx = sa;
    if (std::abs(sb.p22) < std::abs(sx.p22)) x = b, sx = sb;
    return finish(x, sx);
}

} // namespace

UniaxialResponse solveUniaxial(const EnergyDensity& density, double stretch, double lateralGuess) {
    checkStretch("sim::solveUniaxial(): ", stretch);
    return solve(AxialEvaluator(density), stretch, lateralGuess).response;
}

const char* loadCaseName(LoadCase c) {
    switch (c) {
    case LoadCase::Equibiaxial:
        return "equibiaxial";
    case LoadCase::PlanarShear:
        return "planar shear";
    default:
        return "uniaxial";
    }
}

UniaxialResponse solveLoadCase(const EnergyDensity& density, LoadCase c, double stretch, double lateralGuess) {
    checkStretch("sim::solveLoadCase(): ", stretch);
    return solve(AxialEvaluator(density, c), stretch, lateralGuess).response;
}

UniaxialResponse uniaxialNominalStress(const EnergyDensity& density, double stretch) {
    constexpr const char* where = "sim::uniaxialNominalStress(): ";
    checkStretch(where, stretch);
    const Solve s = solve(AxialEvaluator(density), stretch, 0.0);
    if (s.response.solved) return s.response;
    const std::string head =
        std::string(where) + "density '" + density.name() + "', stretch " + formatNumber(stretch, 12) + ": ";
    if (s.notFinite)
        throw InputError(head + "the lateral stress is not finite at lateral stretch t = " + formatNumber(s.lastT, 6));
    const double lo = std::min(s.firstT, s.lastT), hi = std::max(s.firstT, s.lastT);
    const bool firstLow = s.firstT <= s.lastT;
    throw InputError(head + "no lateral stretch in [" + formatNumber(lo, 6) + ", " + formatNumber(hi, 6) +
                     "] frees the lateral faces (P22 = " + formatNumber(firstLow ? s.firstP22 : s.lastP22, 6) +
                     " Pa at t = " + formatNumber(lo, 6) + ", " + formatNumber(firstLow ? s.lastP22 : s.firstP22, 6) +
                     " Pa at t = " + formatNumber(hi, 6) + ")");
}

ShearResponse simpleShearStress(const EnergyDensity& density, double gamma) {
    if (!std::isfinite(gamma))
        throw std::invalid_argument("sim::simpleShearStress(): shear " + formatNumber(gamma, 12) + " must be finite");
    Mat3 F = Mat3::Identity();
    F(0, 1) = gamma;
    const Mat3 P = density.stress(F);
    ShearResponse r;
    r.shear = gamma;
    r.shearStress = P(0, 1);
    r.normalStress[0] = P(0, 0);
    r.normalStress[1] = P(1, 1);
    r.normalStress[2] = P(2, 2);
    return r;
}

void sampleResponsesInto(const EnergyDensity& density, const ResponseSampling& sampling, ResponseCurves& out) {
    constexpr const char* where = "sim::sampleResponsesInto(): ";
    if (sampling.stretchCount < 0 || sampling.shearCount < 0)
        throw std::invalid_argument(std::string(where) + "stretchCount " + std::to_string(sampling.stretchCount) +
                                    " and shearCount " + std::to_string(sampling.shearCount) + " must not be negative");
    if (sampling.stretchCount > 0 && !(std::isfinite(sampling.stretchMin) && std::isfinite(sampling.stretchMax) &&
                                       sampling.stretchMin > 0 && sampling.stretchMin < sampling.stretchMax))
        throw std::invalid_argument(std::string(where) + "stretch range [" + formatNumber(sampling.stretchMin, 12) +
                                    ", " + formatNumber(sampling.stretchMax, 12) +
                                    "] must be finite with 0 < stretchMin < stretchMax");
    if (sampling.shearCount > 0 && !(std::isfinite(sampling.shearMax) && sampling.shearMax > 0))
        throw std::invalid_argument(std::string(where) + "shearMax " + formatNumber(sampling.shearMax, 12) +
                                    " must be finite and positive");

    const auto n = static_cast<std::size_t>(sampling.stretchCount);
    out.stretch.resize(n);
    out.nominalStress.resize(n);
    out.lateralStretch.resize(n);
    out.solved.resize(n);
    out.unsolved = 0;
    const AxialEvaluator eval(density);
    const double step = n > 1 ? (sampling.stretchMax - sampling.stretchMin) / static_cast<double>(n - 1) : 0.0;
    double guess = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const double lambda = i + 1 == n && n > 1 ? sampling.stretchMax : sampling.stretchMin + step * i;
        const UniaxialResponse r = solve(eval, lambda, guess).response;
        out.stretch[i] = lambda;
        out.nominalStress[i] = r.nominalStress;
        out.lateralStretch[i] = r.lateralStretch;
        out.solved[i] = r.solved ? 1 : 0;
        if (!r.solved) ++out.unsolved;
        guess = r.solved ? r.lateralStretch : 0.0;
    }

    const auto m = static_cast<std::size_t>(sampling.shearCount);
    out.shear.resize(m);
    out.shearStress.resize(m);
    const double shearStep = m > 1 ? sampling.shearMax / static_cast<double>(m - 1) : 0.0;
    Mat3 F = Mat3::Identity();
    for (std::size_t i = 0; i < m; ++i) {
        const double gamma = i + 1 == m && m > 1 ? sampling.shearMax : shearStep * i;
        F(0, 1) = gamma;
        out.shear[i] = gamma;
        out.shearStress[i] = density.stress(F)(0, 1);
    }
}

ResponseCurves sampleResponses(const EnergyDensity& density, const ResponseSampling& sampling) {
    ResponseCurves out;
    sampleResponsesInto(density, sampling, out);
    return out;
}

} // namespace viscera::sim
