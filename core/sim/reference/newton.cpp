#include "sim/reference/newton.hpp"

#include "sim/fem/sparse_cholesky.hpp"
#include "sim/util/format.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>

namespace viscera::sim {
Mat3 tetTermGradientColumns(const StepProblem& p, size_t t, const std::array<Vec3, 4>& xe, double scale) {
    Mat3 ds;
    for (int k = 0; k < 3; ++k)
        ds.col(k) = xe[k + 1] - xe[0];
    const Mat3& dmInv = p.dmInv[t];
    return scale * p.model->energyDensityGradient(ds * dmInv) * dmInv.transpose();
}

namespace {

using Vec12 = Eigen::Matrix<double, 12, 1>;
using Mat12 = Eigen::Matrix<double, 12, 12>;
using Clock = std::chrono::steady_clock;

constexpr const char* kWhere = "sim::solveNewton(): ";

double secondsSince(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

double infNorm(const std::vector<Vec3>& v) {
    double n = 0;
    for (const Vec3& a : v)
        n = std::max(n, a.cwiseAbs().maxCoeff());
    return n;
}

bool allFinite(const std::vector<Vec3>& v) {
    for (const Vec3& a : v)
        if (!a.allFinite()) return false;
    return true;
}

void checkProblem(const StepProblem& p, const std::vector<Vec3>& x0) {
    const size_t nv = p.xTilde.size();
    auto fail = [](const std::string& why) { throw std::invalid_argument(kWhere + why); };
    if (!(p.h > 0) || !std::isfinite(p.h)) fail("step h " + formatNumber(p.h, 3) + " must be positive");
    if (!p.model) fail("problem has no constraint model");
    if (x0.size() != nv) fail("x0 has " + std::to_string(x0.size()) + " nodes, the problem has " + std::to_string(nv));
    if (p.mass.size() != nv || p.fixed.size() != nv)
        fail("mass (" + std::to_string(p.mass.size()) + ") and fixed (" + std::to_string(p.fixed.size()) +
             ") must have one entry per node (" + std::to_string(nv) + ")");
    const size_t nt = p.tets.size();
    if (p.dmInv.size() != nt || p.volume.size() != nt || p.weight.size() != nt)
        fail("dmInv, volume and weight must have one entry per tet (" + std::to_string(nt) + ")");
    for (size_t i = 0; i < nv; ++i)
        if (!(p.mass[i] >= 0) || !std::isfinite(p.mass[i]))
            fail("node " + std::to_string(i) + " has mass " + formatNumber(p.mass[i], 3) +
                 " (must be finite and >= 0)");
    for (size_t t = 0; t < nt; ++t) {
        for (int32_t v : p.tets[t])
            if (v < 0 || static_cast<size_t>(v) >= nv)
                fail("tet " + std::to_string(t) + " references node " + std::to_string(v) + " (problem has " +
                     std::to_string(nv) + " nodes)");
        if (!(p.volume[t] > 0) || !std::isfinite(p.volume[t]))
            fail("tet " + std::to_string(t) + " has rest volume " + formatNumber(p.volume[t], 3) +
                 " m^3 (must be positive)");
        if (!(p.weight[t] >= 0) || !std::isfinite(p.weight[t]))
            fail("tet " + std::to_string(t) + " has stiffness weight " + formatNumber(p.weight[t], 3) +
                 " (must be finite and >= 0)");
        if (!p.dmInv[t].allFinite()) fail("tet " + std::to_string(t) + " has a non-finite dmInv");
    }
}

/// Numeric factorization of `values` with the analysed pattern; the Newton wording of a Hessian
/// that is not positive definite (notPositiveDefinite tells that case apart).
bool factorizeHessian(SparseCholesky& llt, const std::vector<double>& values, std::string& error,
                      bool* notPositiveDefinite = nullptr) {
    bool indefinite = false;
    if (llt.factorize(values, error, &indefinite)) return true;
    if (indefinite)
        error = "CHOLMOD: the Hessian is not positive definite (failed at column " +
                std::to_string(llt.failedColumn()) + " of " + std::to_string(llt.size()) + ")";
    if (notPositiveDefinite) *notPositiveDefinite = indefinite;
    return false;
}

/// Gradient (12) of the tet term h² V w Ψ(F) with respect to its four node positions.
Vec12 elementGradient(const StepProblem& p, size_t t, const std::array<Vec3, 4>& xe, double scale) {
    const Mat3 G = tetTermGradientColumns(p, t, xe, scale);
    Vec12 g;
    g.segment<3>(0) = -(G.col(0) + G.col(1) + G.col(2));
    for (int k = 0; k < 3; ++k)
        g.segment<3>(3 * (k + 1)) = G.col(k);
    return g;
}

/// Sparse assembly of H = M + Σ Π⁺(H_e) over the fixed pattern of the problem.
class HessianAssembler {
public:
    HessianAssembler(const StepProblem& p, const NewtonSettings& s) : m_p(p) {
        const size_t nv = p.xTilde.size();
        const size_t n = 3 * nv;
        // Active nodes carry unknowns; fixed nodes and nodes with neither mass nor tets become
        // identity rows.
        std::vector<uint8_t> inTet(nv, 0);
        for (size_t t = 0; t < p.tets.size(); ++t)
            for (int32_t v : p.tets[t])
                inTet[v] = 1;
        m_active.resize(nv);
        for (size_t i = 0; i < nv; ++i)
            m_active[i] = !p.fixed[i] && (p.mass[i] > 0 || inTet[i]);

        std::vector<std::vector<int>> rows(n);
        for (size_t d = 0; d < n; ++d)
            rows[d].push_back(static_cast<int>(d));
        for (const Tet& e : p.tets)
            for (int a = 0; a < 4; ++a)
                for (int b = 0; b < 4; ++b) {
                    if (!m_active[e[a]] || !m_active[e[b]]) continue;
                    for (int da = 0; da < 3; ++da)
                        for (int db = 0; db < 3; ++db) {
                            const int r = 3 * e[a] + da, c = 3 * e[b] + db;
                            if (r <= c) rows[c].push_back(r);
                        }
                }
        std::vector<int>& colPtr = m_pattern.colPtr;
        std::vector<int>& rowIdx = m_pattern.rowIdx;
        colPtr.assign(n + 1, 0);
        for (size_t c = 0; c < n; ++c) {
            auto& col = rows[c];
            std::sort(col.begin(), col.end());
            col.erase(std::unique(col.begin(), col.end()), col.end());
            colPtr[c + 1] = colPtr[c] + static_cast<int>(col.size());
        }
        rowIdx.reserve(colPtr[n]);
        for (const auto& col : rows)
            rowIdx.insert(rowIdx.end(), col.begin(), col.end());
        auto find = [&](int r, int c) { return m_pattern.find(r, c); }; // every (r, c) is present
        m_diag.resize(n);
        for (size_t d = 0; d < n; ++d)
            m_diag[d] = find(static_cast<int>(d), static_cast<int>(d));
        m_scatter.assign(p.tets.size() * 144, -1);
        m_fdStep.resize(p.tets.size());
        for (size_t t = 0; t < p.tets.size(); ++t) {
            const Tet& e = p.tets[t];
            for (int i = 0; i < 12; ++i)
                for (int j = 0; j < 12; ++j) {
                    if (!m_active[e[i / 3]] || !m_active[e[j / 3]]) continue;
                    const int r = 3 * e[i / 3] + i % 3, c = 3 * e[j / 3] + j % 3;
                    if (r <= c) m_scatter[t * 144 + i * 12 + j] = find(r, c);
                }
            m_fdStep[t] = s.fdStep * std::cbrt(6.0 * p.volume[t]);
        }
    }

    const UpperPattern& pattern() const { return m_pattern; }
    bool active(size_t node) const { return m_active[node] != 0; }

    size_t nonZeros() const { return m_pattern.rowIdx.size(); }

    /// Writes the values (pattern order) of M + Σ Π⁺(H_e) into `projected` and, when `exact` is
    /// not null, of M + Σ H_e into `exact`. False on a non-finite entry.
    bool assemble(const std::vector<Vec3>& x, double* projected, double* exact) const {
        std::fill_n(projected, nonZeros(), 0.0);
        if (exact) std::fill_n(exact, nonZeros(), 0.0);
        for (size_t i = 0; i < m_active.size(); ++i)
            for (int d = 0; d < 3; ++d) {
                const double diag = m_active[i] ? m_p.mass[i] : 1.0;
                projected[m_diag[3 * i + d]] = diag;
                if (exact) exact[m_diag[3 * i + d]] = diag;
            }
        const double h2 = m_p.h * m_p.h;
        Eigen::SelfAdjointEigenSolver<Mat12> eig;
        for (size_t t = 0; t < m_p.tets.size(); ++t) {
            const double scale = h2 * m_p.volume[t] * m_p.weight[t];
            if (scale == 0) continue;
            const Tet& e = m_p.tets[t];
            std::array<Vec3, 4> xe = {x[e[0]], x[e[1]], x[e[2]], x[e[3]]};
            Mat12 H;
            for (int j = 0; j < 12; ++j) {
                double& coord = xe[j / 3][j % 3];
                const double x0 = coord;
                const double plus = x0 + m_fdStep[t], minus = x0 - m_fdStep[t];
                coord = plus;
                const Vec12 gp = elementGradient(m_p, t, xe, scale);
                coord = minus;
                const Vec12 gm = elementGradient(m_p, t, xe, scale);
                coord = x0;
                H.col(j) = (gp - gm) / (plus - minus); // the representable step, not 2ε
            }
            H = 0.5 * (H + H.transpose()).eval();
            if (!H.allFinite()) return false;
            const int* map = &m_scatter[t * 144];
            if (exact)
                for (int i = 0; i < 12; ++i)
                    for (int j = 0; j < 12; ++j)
                        if (map[i * 12 + j] >= 0) exact[map[i * 12 + j]] += H(i, j);
            eig.compute(H);
            if (eig.info() != Eigen::Success) return false;
            if (eig.eigenvalues().minCoeff() < 0) {
                const Vec12 clamped = eig.eigenvalues().cwiseMax(0.0);
                H = eig.eigenvectors() * clamped.asDiagonal() * eig.eigenvectors().transpose();
            }
            for (int i = 0; i < 12; ++i)
                for (int j = 0; j < 12; ++j)
                    if (map[i * 12 + j] >= 0) projected[map[i * 12 + j]] += H(i, j);
        }
        return true;
    }

private:
    const StepProblem& m_p;
    std::vector<uint8_t> m_active;
    UpperPattern m_pattern;
    std::vector<int> m_diag, m_scatter;
    std::vector<double> m_fdStep;
};

} // namespace

void validate(const NewtonSettings& s) {
    auto fail = [](const std::string& why) { throw std::invalid_argument(kWhere + why); };
    if (!(s.tolerance > 0) || !std::isfinite(s.tolerance))
        fail("tolerance " + formatNumber(s.tolerance, 3) + " must be positive");
    if (!(s.relativeTolerance > 0 && s.relativeTolerance <= 1))
        fail("relative_tolerance " + formatNumber(s.relativeTolerance, 3) + " must be in (0, 1]");
    if (s.maxIterations < 1) fail("max_iterations " + std::to_string(s.maxIterations) + " must be >= 1");
    if (!(s.armijo > 0 && s.armijo < 1)) fail("armijo " + formatNumber(s.armijo, 3) + " must be in (0, 1)");
    if (!(s.backtrack > 0 && s.backtrack < 1)) fail("backtrack " + formatNumber(s.backtrack, 3) + " must be in (0, 1)");
    if (s.maxBacktracks < 0) fail("max_backtracks " + std::to_string(s.maxBacktracks) + " must be >= 0");
    if (!(s.fdStep > 0 && s.fdStep < 0.1)) fail("fd_step " + formatNumber(s.fdStep, 3) + " must be in (0, 0.1)");
    if (!(s.stepTolerance >= 0) || !std::isfinite(s.stepTolerance))
        fail("step_tolerance " + formatNumber(s.stepTolerance, 3) + " must be finite and >= 0");
}

const char* newtonStatusName(NewtonStatus status) {
    switch (status) {
    case NewtonStatus::Converged:
        return "converged";
    case NewtonStatus::Stalled:
        return "stalled";
    case NewtonStatus::MaxIterations:
        return "max_iterations";
    case NewtonStatus::FactorizationFailed:
        return "factorization_failed";
    case NewtonStatus::NonFinite:
        return "non_finite";
    case NewtonStatus::Cancelled:
        return "cancelled";
    }
    return "unknown";
}

NewtonResult solveNewton(const StepProblem& p, const std::vector<Vec3>& x0, const NewtonSettings& s) {
    validate(s);
    checkProblem(p, x0);
    const auto start = Clock::now();
    const size_t nv = x0.size();
    NewtonResult r;
    r.x = x0;
    for (size_t i = 0; i < nv; ++i)
        if (p.fixed[i]) r.x[i] = p.xTilde[i];
    auto finish = [&](NewtonStatus status, std::string message) {
        r.status = status;
        r.message = std::move(message);
        r.totalSeconds = secondsSince(start);
        return std::move(r); // r is not used after finish()
    };
    if (!allFinite(r.x) || !allFinite(p.xTilde))
        return finish(NewtonStatus::NonFinite, "x0 or xTilde has a non-finite coordinate");

    std::vector<Vec3> g, gTry;
    r.f = p.objective(r.x);
    p.gradientInto(r.x, g);
    double gNorm = infNorm(g);
    if (!std::isfinite(r.f) || !std::isfinite(gNorm))
        return finish(NewtonStatus::NonFinite, "f or its gradient is not finite at x0");
    auto record = [&] {
        r.objectives.push_back(r.f);
        r.gradientNorms.push_back(gNorm);
        r.seconds.push_back(secondsSince(start));
    };
    record();
    const double absoluteThreshold = s.tolerance * std::max(1.0, gNorm);
    const double threshold = std::min(absoluteThreshold, s.relativeTolerance * gNorm);
    // No further progress: converged when the absolute test holds (the relative one asked for
    // more than rounding allows), stalled otherwise.
    auto stall = [&](const std::string& why) {
        if (gNorm <= absoluteThreshold)
            return finish(NewtonStatus::Converged, "relative tolerance not reached, at the rounding floor: " + why);
        return finish(NewtonStatus::Stalled, why);
    };
    if (gNorm <= threshold) return finish(NewtonStatus::Converged, {});

    HessianAssembler assembler(p, s);
    std::string error;
    const std::unique_ptr<SparseCholesky> llt = SparseCholesky::tryCreate(assembler.pattern(), error);
    if (!llt) return finish(NewtonStatus::FactorizationFailed, error);

    double meanSize = 0;
    for (double v : p.volume)
        meanSize += std::cbrt(6.0 * v);
    meanSize /= std::max<size_t>(1, p.volume.size());

    const bool tryExact = s.hessian == NewtonHessian::ExactWhenDefinite;
    std::vector<double> projected(assembler.nonZeros()), exact(tryExact ? assembler.nonZeros() : 0);
    std::vector<double> d(3 * nv);
    std::vector<Vec3> xTry(nv);
    constexpr double eps = std::numeric_limits<double>::epsilon();
    for (int k = 0; k < s.maxIterations; ++k) {
        if (s.cancel && s.cancel->load(std::memory_order_relaxed))
            return finish(NewtonStatus::Cancelled, "cancelled at iteration " + std::to_string(k));
        if (!assembler.assemble(r.x, projected.data(), tryExact ? exact.data() : nullptr))
            return finish(NewtonStatus::NonFinite, "element Hessian not finite at iteration " + std::to_string(k));
        bool factored = false;
        if (tryExact) {
            bool indefinite = false;
            factored = factorizeHessian(*llt, exact, error, &indefinite);
            if (!factored && !indefinite) return finish(NewtonStatus::FactorizationFailed, error);
        }
        if (!factored) {
            if (!factorizeHessian(*llt, projected, error)) return finish(NewtonStatus::FactorizationFailed, error);
            ++r.projectedSteps;
        }
        for (size_t i = 0; i < nv; ++i)
            for (int c = 0; c < 3; ++c)
                d[3 * i + c] = assembler.active(i) ? -g[i][c] : 0.0;
        if (!llt->solveInPlace(d.data(), 1, error)) return finish(NewtonStatus::FactorizationFailed, error);
        double gd = 0, dNorm = 0;
        for (size_t i = 0; i < nv; ++i)
            for (int c = 0; c < 3; ++c) {
                gd += g[i][c] * d[3 * i + c];
                dNorm = std::max(dNorm, std::abs(d[3 * i + c]));
            }
        if (!std::isfinite(gd)) return finish(NewtonStatus::NonFinite, "Newton direction not finite");
        if (!(gd < 0)) return stall("Newton direction is not a descent direction at iteration " + std::to_string(k));

        // Backtracking Armijo. Once the predicted decrease is below the rounding noise of f, f can
        // no longer rank trial points; the full step is then accepted when f stays within the noise
        // and the gradient still shrinks (the quadratic-convergence tail).
        const double fNoise = 64 * eps * std::abs(r.f);
        double alpha = 1, fTry = 0;
        bool accepted = false;
        for (int b = 0; b <= s.maxBacktracks; ++b, alpha *= s.backtrack) {
            for (size_t i = 0; i < nv; ++i)
                xTry[i] = r.x[i] + alpha * Vec3(d[3 * i], d[3 * i + 1], d[3 * i + 2]);
            fTry = p.objective(xTry);
            if (!std::isfinite(fTry)) continue;
            if (fTry <= r.f + s.armijo * alpha * gd) {
                accepted = true;
            } else if (b == 0 && -gd <= fNoise && fTry <= r.f + fNoise) {
                p.gradientInto(xTry, gTry);
                accepted = infNorm(gTry) < gNorm;
                if (!accepted) break;
            }
            if (accepted) break;
        }
        if (!accepted)
            return stall("line search found no decrease of f at iteration " + std::to_string(k) + " (|grad f| " +
                         formatNumber(gNorm, 3) + ")");
        std::swap(r.x, xTry);
        r.f = fTry;
        p.gradientInto(r.x, g);
        gNorm = infNorm(g);
        ++r.iterations;
        record();
        if (!std::isfinite(gNorm)) return finish(NewtonStatus::NonFinite, "gradient not finite");
        if (gNorm <= threshold) return finish(NewtonStatus::Converged, {});
        if (alpha * dNorm <= s.stepTolerance * std::max(infNorm(r.x), meanSize))
            return stall("step below floating-point resolution at iteration " + std::to_string(k));
    }
    return finish(NewtonStatus::MaxIterations, "no convergence in " + std::to_string(s.maxIterations) +
                                                   " iterations (|grad f| " + formatNumber(gNorm, 3) + ", threshold " +
                                                   formatNumber(threshold, 3) + ")");
}

} // namespace viscera::sim
