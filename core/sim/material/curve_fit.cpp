#include "sim/material/curve_fit.hpp"

#include "sim/material/material_response.hpp"
#include "sim/util/error.hpp"
#include "sim/util/format.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <stdexcept>

namespace viscera::sim {

namespace {

constexpr const char* kWhere = "sim::fitUniaxial(): ";

/// One fitted curve: where its parameters sit in θ and how they map to control values.
struct CurveParameters {
    std::optional<MonotoneCurve> ValanisLandelCurves::*member = nullptr;
    std::size_t offset = 0; ///< first entry in θ
    std::size_t rest = 0;   ///< index of the pinned control point (x = 1)
    double restValue = 0;
    double scale = 1;
    bool increasing = false;
    std::vector<CurvePoint> points; ///< start points (x kept; y rebuilt)
    std::size_t count() const { return points.size() - 1; }
};

constexpr double kLogRange = 30.0; ///< θ of an increment stays within log(scale) ± this
/// Largest change of one θ per step: a factor e³ on an increment, three scales on a free value.
constexpr double kMaxStep = 3.0;
constexpr int kScaleIterations = 30; ///< at most this many of FitOptions::maxIterations go to phase 1

CurveParameters describe(const ValanisLandelCurves& start, std::optional<MonotoneCurve> ValanisLandelCurves::*member,
                         std::size_t offset) {
    const MonotoneCurve& c = *(start.*member);
    CurveParameters p;
    p.member = member;
    p.offset = offset;
    p.points = c.controlPoints();
    p.increasing = c.shape() == CurveShape::StrictlyIncreasing;
    const auto it = std::find_if(p.points.begin(), p.points.end(), [](const CurvePoint& q) { return q.x == 1.0; });
    if (it == p.points.end())
        throw std::invalid_argument(std::string(kWhere) + "curve " + c.name() +
                                    " has no control point at x = 1 (the pinned rest point)");
    p.rest = static_cast<std::size_t>(it - p.points.begin());
    p.restValue = it->y;
    double scale = std::abs(c.derivative(1.0));
    for (const CurvePoint& q : p.points)
        scale = std::max(scale, std::abs(q.y));
    p.scale = scale > 0 ? scale : 1.0;
    return p;
}

void toTheta(const CurveParameters& p, Eigen::VectorXd& theta) {
    const auto& pts = p.points;
    for (std::size_t k = 0; k + 1 < pts.size(); ++k) {
        // Increasing: θ_k ↔ increment between points k and k+1. Unconstrained: θ ↔ every point
        // but the rest one, in order.
        double v;
        if (p.increasing) {
            v = std::log(pts[k + 1].y - pts[k].y);
        } else {
            const std::size_t j = k < p.rest ? k : k + 1;
            v = (pts[j].y - p.restValue) / p.scale;
        }
        theta(static_cast<Eigen::Index>(p.offset + k)) = v;
    }
}

void projectTheta(const CurveParameters& p, Eigen::VectorXd& theta) {
    if (!p.increasing) return;
    const double centre = std::log(p.scale);
    for (std::size_t k = 0; k < p.count(); ++k) {
        double& v = theta(static_cast<Eigen::Index>(p.offset + k));
        v = std::clamp(v, centre - kLogRange, centre + kLogRange);
    }
}

/// Control values from θ (rest value exactly kept).
std::vector<CurvePoint> fromTheta(const CurveParameters& p, const Eigen::VectorXd& theta) {
    std::vector<CurvePoint> pts = p.points;
    const auto th = [&](std::size_t k) { return theta(static_cast<Eigen::Index>(p.offset + k)); };
    pts[p.rest].y = p.restValue;
    if (p.increasing) {
        for (std::size_t k = p.rest; k + 1 < pts.size(); ++k)
            pts[k + 1].y = pts[k].y + std::exp(th(k));
        for (std::size_t k = p.rest; k-- > 0;)
            pts[k].y = pts[k + 1].y - std::exp(th(k));
    } else {
        for (std::size_t k = 0; k + 1 < pts.size(); ++k)
            pts[k < p.rest ? k : k + 1].y = p.restValue + p.scale * th(k);
    }
    return pts;
}

double valueAt1(const std::optional<MonotoneCurve>& c) {
    return c ? c->value(1.0) : 0.0;
}
double slopeAt1(const std::optional<MonotoneCurve>& c) {
    return c ? c->derivative(1.0) : 0.0;
}

/// Small-strain Lamé μ_eff, λ_eff of curves (ValanisLandelDensity's formulas, without its checks).
std::pair<double, double> lameAtRest(const ValanisLandelCurves& c) {
    const double g1 = valueAt1(c.gPrime), g2 = slopeAt1(c.gPrime), h1 = valueAt1(c.hPrime);
    return {0.5 * (slopeAt1(c.fPrime) + g2 - g1 - h1), g2 + g1 + slopeAt1(c.hPrime) + h1};
}

/// FitCurves::FPrimeKeepingPoisson: h′ scaled about h′(1) so that λ_eff/μ_eff stays the start's.
class PoissonKeeper {
public:
    explicit PoissonKeeper(const ValanisLandelCurves& start) : m_h(*start.hPrime) {
        const auto [mu, lambda] = lameAtRest(start);
        m_ratio = lambda / mu;
        m_rest = m_h.value(1.0);
        m_slope = m_h.derivative(1.0);
    }
    /// `c` (f′ fitted, h′ the start's) with h′ scaled; false when no positive scale keeps ν.
    bool apply(ValanisLandelCurves& c) const {
        const auto [mu, lambda] = lameAtRest(c);
        const double k = 1.0 + (m_ratio * mu - lambda) / m_slope;
        if (!(k > 0) || !std::isfinite(k)) return false;
        std::vector<CurvePoint> pts = m_h.controlPoints();
        for (CurvePoint& q : pts)
            q.y = q.y == m_rest ? m_rest : m_rest + k * (q.y - m_rest); // the rest point kept exactly
        c.hPrime = MonotoneCurve(m_h.name(), std::move(pts), m_h.shape(), m_h.context());
        return true;
    }

private:
    const MonotoneCurve& m_h;
    double m_ratio = 0, m_rest = 0, m_slope = 1;
};

/// θ ↔ curves, and the weighted data residuals of a θ.
class Problem {
public:
    Problem(const ValanisLandelCurves& start, const UniaxialData& data, const FitOptions& options)
        : m_start(start), m_data(data) {
        std::size_t offset = 0;
        m_params.push_back(describe(start, &ValanisLandelCurves::fPrime, offset));
        offset += m_params.back().count();
        if (options.curves == FitCurves::FPrimeAndHPrime) {
            m_params.push_back(describe(start, &ValanisLandelCurves::hPrime, offset));
            offset += m_params.back().count();
        }
        m_unknowns = offset;
        if (options.curves == FitCurves::FPrimeKeepingPoisson) m_keeper.emplace(start);
        const std::size_t n = data.size();
        double maxAbs = 0;
        for (double s : data.nominalStress)
            maxAbs = std::max(maxAbs, std::abs(s));
        m_floor = maxAbs > 0 ? 1e-3 * maxAbs : 1.0;
        m_weight.resize(static_cast<Eigen::Index>(n));
        m_energy = 0;
        for (std::size_t i = 0; i < n; ++i) {
            const double w = options.weighting == FitWeighting::Relative
                                 ? 1.0 / std::max(std::abs(data.nominalStress[i]), m_floor)
                                 : 1.0;
            m_weight(static_cast<Eigen::Index>(i)) = w;
            m_energy += (w * data.nominalStress[i]) * (w * data.nominalStress[i]);
        }
        m_lateral.assign(n, 0.0);
    }

    std::size_t unknowns() const { return m_unknowns; }
    std::size_t rows() const { return m_data.size(); }
    double floor() const { return m_floor; }
    double energy() const { return m_energy; } ///< Σ (w_i σ_i)²
    int evaluations() const { return m_evaluations; }
    const std::vector<CurveParameters>& curveParameters() const { return m_params; }

    Eigen::VectorXd theta() const {
        Eigen::VectorXd t(static_cast<Eigen::Index>(m_unknowns));
        for (const auto& p : m_params)
            toTheta(p, t);
        return t;
    }
    void project(Eigen::VectorXd& theta) const {
        for (const auto& p : m_params)
            projectTheta(p, theta);
    }

    /// Curves at θ, or nothing when they break the shape rule (rounding) or are non-finite.
    std::optional<ValanisLandelCurves> curves(const Eigen::VectorXd& theta) const {
        ValanisLandelCurves c = m_start;
        try {
            for (const auto& p : m_params) {
                const MonotoneCurve& old = *(m_start.*p.member);
                c.*p.member = MonotoneCurve(old.name(), fromTheta(p, theta), old.shape(), old.context());
            }
            if (m_keeper && !m_keeper->apply(c)) return std::nullopt;
        } catch (const InputError&) {
            return std::nullopt;
        }
        return c;
    }

    /// Weighted data residuals into the first rows() entries of r (and the stresses) at θ;
    /// false when θ is not admissible (no valid density, a data point without a uniaxial
    /// state, a non-finite residual).
    bool residuals(const Eigen::VectorXd& theta, Eigen::VectorXd& r, std::vector<double>* stress = nullptr) {
        ++m_evaluations;
        const std::optional<ValanisLandelCurves> c = curves(theta);
        if (!c) return false;
        std::optional<ValanisLandelDensity> density;
        try {
            density.emplace("fit", *c);
        } catch (const InputError&) {
            return false;
        }
        const std::size_t n = m_data.size();
        m_trialLateral.resize(n);
        if (stress) stress->resize(n);
        for (std::size_t i = 0; i < n; ++i) {
            const UniaxialResponse u = solveLoadCase(*density, caseOf(i), m_data.stretch[i], m_lateral[i]);
            if (!u.solved) return false;
            const double ri = (u.nominalStress - m_data.nominalStress[i]) * m_weight(static_cast<Eigen::Index>(i));
            if (!std::isfinite(ri)) return false;
            r(static_cast<Eigen::Index>(i)) = ri;
            m_trialLateral[i] = u.lateralStretch;
            if (stress) (*stress)[i] = u.nominalStress;
        }
        return true;
    }
    LoadCase caseOf(std::size_t i) const { return m_data.loadCase.empty() ? LoadCase::Uniaxial : m_data.loadCase[i]; }
    /// The lateral stretches of the last successful residuals() become the warm start.
    void commitLateral() { m_lateral = m_trialLateral; }

private:
    const ValanisLandelCurves& m_start;
    const UniaxialData& m_data;
    std::vector<CurveParameters> m_params;
    std::optional<PoissonKeeper> m_keeper;
    std::size_t m_unknowns = 0;
    double m_floor = 1, m_energy = 0;
    Eigen::VectorXd m_weight;
    std::vector<double> m_lateral, m_trialLateral;
    int m_evaluations = 0;
};

/// A least-squares problem for levenbergMarquardt(): residuals r(p) (false: p not admissible),
/// the projection onto the admissible box, and the commit of an accepted p.
struct LeastSquares {
    std::function<bool(const Eigen::VectorXd&, Eigen::VectorXd&)> residuals;
    std::function<void(Eigen::VectorXd&)> project;
    std::function<void()> accept;
};

struct LmOutcome {
    int iterations = 0;
    FitStop stop = FitStop::IterationLimit;
};

/// Forward-difference Jacobian at p (residuals r there); a column whose forward trial is not
/// admissible uses a backward difference, and is zero when neither is.
Eigen::MatrixXd jacobian(const LeastSquares& ls, const Eigen::VectorXd& p, const Eigen::VectorXd& r) {
    Eigen::MatrixXd J(r.size(), p.size());
    Eigen::VectorXd t = p, rt(r.size());
    for (Eigen::Index k = 0; k < p.size(); ++k) {
        const double h = 1e-6 * std::max(1.0, std::abs(p(k)));
        t(k) = p(k) + h;
        if (ls.residuals(t, rt)) {
            J.col(k) = (rt - r) / h;
        } else {
            t(k) = p(k) - h;
            if (ls.residuals(t, rt))
                J.col(k) = (r - rt) / h;
            else
                J.col(k).setZero();
        }
        t(k) = p(k);
    }
    return J;
}

/// Levenberg–Marquardt from p (admissible, residuals r) with Marquardt scaling and Nielsen's
/// damping update; steps with a component above kMaxStep count as rejected.
LmOutcome levenbergMarquardt(const LeastSquares& ls, Eigen::VectorXd& p, Eigen::VectorXd& r, int maxIterations,
                             double tol) {
    LmOutcome out;
    double cost = 0.5 * r.squaredNorm();
    const double costScale = std::max(cost, std::numeric_limits<double>::min());
    double damping = 1e-3, growth = 2;
    Eigen::VectorXd step, trial, rTrial(r.size());
    for (int iter = 0; iter < maxIterations; ++iter) {
        out.iterations = iter + 1;
        if (cost <= 1e-30 * costScale) {
            out.stop = FitStop::GradientTolerance;
            return out;
        }
        const Eigen::MatrixXd J = jacobian(ls, p, r);
        const Eigen::MatrixXd A = J.transpose() * J;
        const Eigen::VectorXd g = J.transpose() * r;
        // ‖Jᵀr‖∞ against the scale of its entries, ‖J‖ ‖r‖ (MINPACK's gtol).
        if (!(g.cwiseAbs().maxCoeff() > tol * std::sqrt(A.diagonal().maxCoeff()) * r.norm())) {
            out.stop = FitStop::GradientTolerance;
            return out;
        }
        Eigen::VectorXd D = A.diagonal();
        const double dmax = D.maxCoeff();
        for (Eigen::Index k = 0; k < D.size(); ++k)
            D(k) = std::max(D(k), 1e-12 * dmax);
        bool accepted = false;
        double newCost = cost, predicted = 0;
        for (; damping < 1e16; damping *= growth, growth *= 2) {
            Eigen::MatrixXd M = A;
            M.diagonal() += damping * D;
            step = M.ldlt().solve(-g);
            if (!(step.cwiseAbs().maxCoeff() <= kMaxStep)) continue; // trust region (NaN included)
            trial = p + step;
            ls.project(trial);
            step = trial - p;
            if (!ls.residuals(trial, rTrial)) continue;
            newCost = 0.5 * rTrial.squaredNorm();
            if (!(newCost < cost)) continue;
            predicted = -(step.dot(g) + 0.5 * step.dot(A * step));
            const double rho = predicted > 0 ? (cost - newCost) / predicted : 0.0;
            damping *= std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * rho - 1.0, 3));
            growth = 2;
            accepted = true;
            break;
        }
        if (!accepted) {
            out.stop = FitStop::NoDescent;
            return out;
        }
        ls.accept();
        const double decrease = cost - newCost;
        const double stepNorm = step.norm(), pNorm = p.norm();
        p = trial;
        r = rTrial;
        cost = newCost;
        if (decrease <= tol * (cost + decrease) && predicted <= tol * (cost + decrease)) {
            out.stop = FitStop::CostTolerance;
            return out;
        }
        if (stepNorm <= tol * (pNorm + tol)) {
            out.stop = FitStop::StepTolerance;
            return out;
        }
    }
    out.stop = FitStop::IterationLimit;
    return out;
}

/// θ of the scale phase: every fitted curve's deviations from its rest value times e^{s_c}.
Eigen::VectorXd scaledTheta(const std::vector<CurveParameters>& params, const Eigen::VectorXd& theta0,
                            const Eigen::VectorXd& s) {
    Eigen::VectorXd theta = theta0;
    for (std::size_t c = 0; c < params.size(); ++c) {
        const CurveParameters& p = params[c];
        auto segment = theta.segment(static_cast<Eigen::Index>(p.offset), static_cast<Eigen::Index>(p.count()));
        const double sc = s(static_cast<Eigen::Index>(c));
        if (p.increasing)
            segment.array() += sc; // increments × e^{s_c}
        else
            segment *= std::exp(sc);
    }
    return theta;
}

void checkInput(const ValanisLandelCurves& start, const UniaxialData& data, const FitOptions& options) {
    const std::string where = kWhere;
    if (data.stretch.size() != data.nominalStress.size())
        throw std::invalid_argument(where + "data has " + std::to_string(data.stretch.size()) + " stretches and " +
                                    std::to_string(data.nominalStress.size()) + " stresses");
    if (data.size() < UniaxialDataLimits::minRows)
        throw std::invalid_argument(where + "data has " + std::to_string(data.size()) + " rows, at least " +
                                    std::to_string(UniaxialDataLimits::minRows) + " are needed");
    if (!data.loadCase.empty() && data.loadCase.size() != data.size())
        throw std::invalid_argument(where + "data has " + std::to_string(data.loadCase.size()) + " test marks for " +
                                    std::to_string(data.size()) + " rows");
    for (std::size_t i = 0; i < data.size(); ++i) {
        const double s = data.stretch[i];
        const bool sameTest = i > 0 && (data.loadCase.empty() || data.loadCase[i] == data.loadCase[i - 1]);
        if (!std::isfinite(s) || !(s > 0) || (sameTest && !(s > data.stretch[i - 1])))
            throw std::invalid_argument(where + "data row " + std::to_string(i) + ": stretch " + formatNumber(s, 12) +
                                        " must be finite, positive and above the previous row's");
        if (!std::isfinite(data.nominalStress[i]))
            throw std::invalid_argument(where + "data row " + std::to_string(i) + ": stress " +
                                        formatNumber(data.nominalStress[i], 12) + " is not finite");
    }
    if (options.maxIterations < 1)
        throw std::invalid_argument(where + "maxIterations " + std::to_string(options.maxIterations) +
                                    " must be at least 1");
    if (!(options.tolerance > 0) || !std::isfinite(options.tolerance))
        throw std::invalid_argument(where + "tolerance " + formatNumber(options.tolerance, 12) +
                                    " must be finite and positive");
    if (!(options.regularization >= 0) || !std::isfinite(options.regularization))
        throw std::invalid_argument(where + "regularization " + formatNumber(options.regularization, 12) +
                                    " must be finite and not negative");
    if (!start.fPrime) throw std::invalid_argument(where + "the start curves have no f' to fit");
    if (options.curves == FitCurves::FPrimeAndHPrime && !start.hPrime)
        throw std::invalid_argument(where + "the start curves have no h' to fit (use FitCurves::FPrime)");
    if (options.curves == FitCurves::FPrimeKeepingPoisson && !(start.hPrime && start.hPrime->derivative(1.0) > 0))
        throw std::invalid_argument(where + "the start curves have no h' rising at 1 to keep nu with (use "
                                            "FitCurves::FPrime)");
}

} // namespace

CurveFitResult fitUniaxial(const ValanisLandelCurves& start, const UniaxialData& data, const FitOptions& options) {
    checkInput(start, data, options);
    Problem problem(start, data, options); // checks the rest points
    // Start state: a valid density with a uniaxial state at every data stretch.
    try {
        ValanisLandelDensity("fit start", start);
    } catch (const InputError& e) {
        throw InputError(std::string(kWhere) + "start curves: " + e.what());
    }
    Eigen::VectorXd theta = problem.theta();
    problem.project(theta);
    Eigen::VectorXd r(static_cast<Eigen::Index>(data.size()));
    if (problem.residuals(theta, r)) {
        problem.commitLateral();
    } else {
        // Name the first data stretch without a uniaxial state.
        const ValanisLandelDensity density("fit start", *problem.curves(theta));
        for (std::size_t i = 0; i < data.size(); ++i)
            if (!solveLoadCase(density, problem.caseOf(i), data.stretch[i]).solved)
                throw InputError(std::string(kWhere) + "start curves: no " + loadCaseName(problem.caseOf(i)) +
                                 " state at stretch " + formatNumber(data.stretch[i], 12) +
                                 (data.line.size() == data.size() ? " (data line " + std::to_string(data.line[i]) + ")"
                                                                  : std::string()));
        throw InputError(std::string(kWhere) + "start curves: the uniaxial stress is not finite at a data stretch");
    }

    CurveFitResult result;
    const Eigen::Index n = static_cast<Eigen::Index>(problem.rows());
    const auto& params = problem.curveParameters();
    // Phase 1: one scale per fitted curve about its rest value (well posed: the start's shape
    // at the data's stiffness). Phase 2: every control value, pulled toward the phase-1 curves.
    const Eigen::VectorXd theta0 = theta;
    Eigen::VectorXd s = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(params.size()));
    LeastSquares scale;
    scale.residuals = [&](const Eigen::VectorXd& q, Eigen::VectorXd& res) {
        Eigen::VectorXd t = scaledTheta(params, theta0, q);
        problem.project(t);
        return problem.residuals(t, res);
    };
    scale.project = [](Eigen::VectorXd& q) { q = q.cwiseMax(-kLogRange).cwiseMin(kLogRange); };
    scale.accept = [&] { problem.commitLateral(); };
    const int scaleBudget = std::min(options.maxIterations, kScaleIterations);
    const LmOutcome first = levenbergMarquardt(scale, s, r, scaleBudget, options.tolerance);
    theta = scaledTheta(params, theta0, s);
    problem.project(theta);

    const Eigen::VectorXd prior = theta;
    const double pull = std::sqrt(options.regularization * std::max(problem.energy(), 1e-300));
    LeastSquares full;
    full.residuals = [&](const Eigen::VectorXd& t, Eigen::VectorXd& res) {
        if (!problem.residuals(t, res)) return false;
        res.tail(t.size()) = pull * (t - prior);
        return true;
    };
    full.project = [&](Eigen::VectorXd& t) { problem.project(t); };
    full.accept = [&] { problem.commitLateral(); };
    Eigen::VectorXd rFull(n + theta.size());
    rFull.head(n) = r;
    rFull.tail(theta.size()).setZero();
    const int fullBudget = options.maxIterations - first.iterations;
    LmOutcome second;
    if (fullBudget > 0) {
        second = levenbergMarquardt(full, theta, rFull, fullBudget, options.tolerance);
    } else {
        second.stop = FitStop::IterationLimit; // phase 2 never ran
    }
    result.iterations = first.iterations + second.iterations;
    result.stop = second.stop;
    result.converged = result.stop != FitStop::IterationLimit;

    // Final figures from the accepted state (admissible by construction).
    result.curves = *problem.curves(theta);
    problem.residuals(theta, r, &result.fittedStress);
    double mean = 0;
    for (double v : data.nominalStress)
        mean += v;
    mean /= static_cast<double>(data.size());
    double sst = 0;
    result.relativeErrorFloor = problem.floor();
    for (std::size_t i = 0; i < data.size(); ++i) {
        const double fitted = result.fittedStress[i];
        const double e = fitted - data.nominalStress[i];
        result.sse += e * e;
        sst += (data.nominalStress[i] - mean) * (data.nominalStress[i] - mean);
        result.maxRelativeError =
            std::max(result.maxRelativeError,
                     std::abs(e) / std::max(std::abs(data.nominalStress[i]), result.relativeErrorFloor));
    }
    result.rSquared = sst > 0 ? 1.0 - result.sse / sst : 1.0 - result.sse / (result.sse + 1.0);
    result.stretchMin = *std::min_element(data.stretch.begin(), data.stretch.end());
    result.stretchMax = *std::max_element(data.stretch.begin(), data.stretch.end());
    result.evaluations = problem.evaluations();
    return result;
}

} // namespace viscera::sim
