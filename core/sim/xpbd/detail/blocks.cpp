#include "sim/xpbd/detail/blocks.hpp"

#include "sim/material/stable_neo_hookean.hpp"
#include "sim/xpbd/coupling.hpp"
#include "sim/xpbd/detail/membrane_kernel.hpp"
#include "sim/xpbd/detail/snh_kernel.hpp"
#include "sim/xpbd/membrane.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

namespace viscera::sim::detail {
namespace {

/// Edge matrix Ds = [x1 − x0, x2 − x0, x3 − x0] of tet e at the particle positions, m.
Mat3 edgeMatrix(const double* xw, const Tet& e) {
    Mat3 ds;
    for (int k = 0; k < 3; ++k)
        ds.col(k) = particlePosition(xw, e[k + 1]) - particlePosition(xw, e[0]);
    return ds;
}

/// Adds column k of G (= ∂C/∂F Dm⁻ᵀ times λ) to particle e[k+1] of f and minus their sum to e[0]
/// (f: 3 per particle).
void scatterTetGradient(const Tet& e, const Mat3& G, double* f) {
    for (int k = 0; k < 3; ++k)
        for (int r = 0; r < 3; ++r) {
            f[3 * size_t(e[k + 1]) + r] += G(r, k);
            f[3 * size_t(e[0]) + r] -= G(r, k);
        }
}

// ---- stable Neo-Hookean, packed ---------------------------------------------------------------

class SnhBlock final : public Block {
public:
    SnhBlock(ElasticTets t, const StableNeoHookeanModel& m, bool avx2)
        : m_t(std::move(t)), m_mu(m.mu()), m_lambda(m.lambda()), m_gamma(m.gamma()), m_avx2(avx2),
          m_active(m_t.tets.size(), 1) {}

    size_t unitCount() const override { return m_t.tets.size(); }
    int unitParticles(size_t u, int32_t* out) const override {
        std::copy_n(m_t.tets[u].begin(), 4, out);
        return 4;
    }
    void solve(size_t pb, size_t pe, const SolveContext& ctx) override {
        const SnhParams p{ctx.xw, ctx.h2inv, m_gamma, ctx.first ? 1 : 0, ctx.last ? 0 : 1};
        if (m_avx2)
            snhSolveAvx2(m_packs.data() + pb, pe - pb, p);
        else
            snhSolveScalar(m_packs.data() + pb, pe - pb, p);
    }
    bool addMultiplierForces(size_t pb, size_t pe, const double* xw, double* f) const override {
        for (size_t q = pb; q < pe; ++q) {
            const SnhPack& P = m_packs[q];
            for (int l = 0; l < P.lanes; ++l) {
                const Tet id{P.idx[0][l], P.idx[1][l], P.idx[2][l], P.idx[3][l]};
                const Mat3 ds = edgeMatrix(xw, id);
                Mat3 M;
                for (int r = 0; r < 3; ++r)
                    for (int c = 0; c < 3; ++c)
                        M(r, c) = P.m[3 * r + c][l];
                const Mat3 F = ds * M;
                const double cD = F.norm();
                if (!(cD > 1e-12)) continue;
                Mat3 H; // cofactor of F = ∂ det F / ∂F
                H.col(0) = F.col(1).cross(F.col(2));
                H.col(1) = F.col(2).cross(F.col(0));
                H.col(2) = F.col(0).cross(F.col(1));
                // ∂C/∂F: F/|F| for C_D, cof F for C_H; vertex k+1 gets column k of (∂C/∂F) Dm⁻ᵀ.
                scatterTetGradient(id, (P.lamD[l] / cD * F + P.lamH[l] * H) * M.transpose(), f);
            }
        }
        return true;
    }
    double energy(const double* xw, size_t unitBegin, size_t unitEnd) const override {
        // Ψ relative to rest: μ/2 (|F|² − 3) + λ/2 ((J − γ)² − (1 − γ)²).
        double sum = 0;
        for (size_t u = unitBegin; u < unitEnd; ++u) {
            if (!m_active[u]) continue;
            const Tet& e = m_t.tets[u];
            const Mat3 ds = edgeMatrix(xw, e);
            const Mat3 F = ds * m_t.dmInv[u];
            const double J = F.determinant();
            const double psi = 0.5 * m_mu * (F.squaredNorm() - 3.0) +
                               0.5 * m_lambda * ((J - m_gamma) * (J - m_gamma) - (1 - m_gamma) * (1 - m_gamma));
            sum += m_t.volume[u] * m_t.weight[u] * psi;
        }
        return sum;
    }
    // An inactive tet keeps Dm⁻¹ = 0 in its lane: F = 0, which both kernels skip (|F| ≈ 0).
    bool setUnitActive(size_t u, bool active) override {
        m_active.at(u) = active ? 1 : 0;
        writeLane(u);
        return true;
    }
    bool setUnitRestInverse(size_t u, const double* m) override {
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c)
                m_t.dmInv.at(u)(r, c) = m[3 * r + c];
        writeLane(u);
        return true;
    }

protected:
    void build(const std::vector<int32_t>& slots) override {
        m_slotOf.assign(m_t.tets.size(), 0);
        for (size_t s = 0; s < slots.size(); ++s)
            if (slots[s] >= 0) m_slotOf[slots[s]] = static_cast<uint32_t>(s);
        m_packs.assign(slots.size() / 4, SnhPack{});
        for (size_t q = 0; q < m_packs.size(); ++q) {
            SnhPack& P = m_packs[q];
            P.lanes = 0;
            for (int l = 0; l < 4; ++l) {
                const int32_t u = slots[4 * q + l] >= 0 ? slots[4 * q + l] : slots[4 * q];
                if (slots[4 * q + l] >= 0) ++P.lanes;
                for (int s = 0; s < 4; ++s)
                    P.idx[s][l] = m_t.tets[u][s];
                for (int r = 0; r < 3; ++r)
                    for (int c = 0; c < 3; ++c)
                        P.m[3 * r + c][l] = m_active[u] ? m_t.dmInv[u](r, c) : 0.0;
                const double vw = m_t.volume[u] * m_t.weight[u];
                P.alphaD[l] = 1.0 / (m_mu * vw);
                P.alphaH[l] = 1.0 / (m_lambda * vw);
                P.lamD[l] = P.lamH[l] = 0;
            }
        }
    }

private:
    /// Rewrites Dm⁻¹ of unit u in its pack lane (and in the padding lanes that repeat it).
    void writeLane(size_t u) {
        if (m_packs.empty()) return; // not arranged yet: build() reads m_t and m_active
        const size_t slot = m_slotOf[u];
        SnhPack& P = m_packs[slot / 4];
        const int lane = static_cast<int>(slot % 4);
        for (int l = 0; l < 4; ++l) {
            if (l != lane && !(lane == 0 && l >= P.lanes)) continue;
            for (int r = 0; r < 3; ++r)
                for (int c = 0; c < 3; ++c)
                    P.m[3 * r + c][l] = m_active[u] ? m_t.dmInv[u](r, c) : 0.0;
        }
    }
    ElasticTets m_t;
    double m_mu, m_lambda, m_gamma;
    bool m_avx2;
    std::vector<uint8_t> m_active;  ///< per unit
    std::vector<uint32_t> m_slotOf; ///< per unit: 4 · pack + lane
    std::vector<SnhPack> m_packs;
};

// ---- any TetConstraintModel ---------------------------------------------------------------------

class ModelBlock final : public Block {
public:
    explicit ModelBlock(ElasticTets t) : m_t(std::move(t)) {
        m_count = m_t.model->count();
        m_alpha = m_t.model->compliance();
        m_restDensity = m_t.model->energyDensity(Mat3::Identity());
        m_active.assign(m_t.tets.size(), 1);
    }
    bool setUnitActive(size_t u, bool active) override {
        m_active.at(u) = active ? 1 : 0;
        return true;
    }
    bool setUnitRestInverse(size_t u, const double* m) override {
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c)
                m_t.dmInv.at(u)(r, c) = m[3 * r + c];
        return true;
    }

    size_t unitCount() const override { return m_t.tets.size(); }
    int unitParticles(size_t u, int32_t* out) const override {
        std::copy_n(m_t.tets[u].begin(), 4, out);
        return 4;
    }
    void solve(size_t pb, size_t pe, const SolveContext& ctx) override {
        TetConstraintValues cv;
        for (size_t s = 4 * pb; s < 4 * pe; ++s) {
            Unit& u = m_units[s];
            if (u.unit < 0 || !m_active[u.unit]) continue;
            if (ctx.first) u.lam = {0, 0};
            const Tet& e = m_t.tets[u.unit];
            Vec3 x[4];
            double w[4];
            for (int k = 0; k < 4; ++k) {
                x[k] = particlePosition(ctx.xw, e[k]);
                w[k] = particleInvMass(ctx.xw, e[k]);
            }
            Mat3 ds;
            for (int k = 0; k < 3; ++k)
                ds.col(k) = x[k + 1] - x[0];
            const Mat3& M = m_t.dmInv[u.unit];
            m_t.model->evaluate(ds * M, cv);
            const int n = std::min(cv.count, m_count);
            if (n <= 0) continue;
            Vec3 g[2][4];
            for (int c = 0; c < n; ++c) {
                const Mat3 G = cv.dCdF[c] * M.transpose();
                g[c][0] = -(G.col(0) + G.col(1) + G.col(2));
                for (int k = 0; k < 3; ++k)
                    g[c][k + 1] = G.col(k);
            }
            double A[2][2] = {{0, 0}, {0, 0}};
            for (int k = 0; k < 4; ++k)
                for (int a = 0; a < n; ++a)
                    for (int b = a; b < n; ++b)
                        A[a][b] += w[k] * g[a][k].dot(g[b][k]);
            double t[2];
            for (int c = 0; c < n; ++c)
                t[c] = m_alpha[c] / u.vw * ctx.h2inv;
            double d[2] = {0, 0};
            if (n == 1) {
                const double den = A[0][0] + t[0];
                if (!(den > 0) || !std::isfinite(den)) continue;
                d[0] = (-cv.C[0] - t[0] * u.lam[0]) / den;
            } else {
                const double a00 = A[0][0] + t[0], a11 = A[1][1] + t[1], a01 = A[0][1];
                const double r0 = -cv.C[0] - t[0] * u.lam[0], r1 = -cv.C[1] - t[1] * u.lam[1];
                const double det = a00 * a11 - a01 * a01;
                if (!(det > 0) || !std::isfinite(det)) continue;
                d[0] = (a11 * r0 - a01 * r1) / det;
                d[1] = (a00 * r1 - a01 * r0) / det;
            }
            for (int c = 0; c < n; ++c)
                u.lam[c] += d[c];
            for (int k = 0; k < 4; ++k) {
                Vec3 dx = d[0] * g[0][k];
                if (n == 2) dx += d[1] * g[1][k];
                moveParticle(ctx.xw, e[k], w[k] * dx);
            }
        }
    }
    bool addMultiplierForces(size_t pb, size_t pe, const double* xw, double* f) const override {
        TetConstraintValues cv;
        for (size_t slot = 4 * pb; slot < 4 * pe; ++slot) {
            const Unit& u = m_units[slot];
            if (u.unit < 0 || !m_active[u.unit]) continue;
            const Tet& e = m_t.tets[u.unit];
            const Mat3 ds = edgeMatrix(xw, e);
            const Mat3& M = m_t.dmInv[u.unit];
            m_t.model->evaluate(ds * M, cv);
            const int n = std::min(cv.count, m_count);
            Mat3 G = Mat3::Zero();
            for (int c = 0; c < n; ++c)
                G += u.lam[c] * cv.dCdF[c];
            scatterTetGradient(e, G * M.transpose(), f);
        }
        return true;
    }
    double energy(const double* xw, size_t unitBegin, size_t unitEnd) const override {
        double sum = 0;
        for (size_t u = unitBegin; u < unitEnd; ++u) {
            if (!m_active[u]) continue;
            const Tet& e = m_t.tets[u];
            const Mat3 ds = edgeMatrix(xw, e);
            sum += m_t.volume[u] * m_t.weight[u] * (m_t.model->energyDensity(ds * m_t.dmInv[u]) - m_restDensity);
        }
        return sum;
    }

protected:
    void build(const std::vector<int32_t>& slots) override {
        m_units.assign(slots.size(), Unit{});
        for (size_t s = 0; s < slots.size(); ++s) {
            m_units[s].unit = slots[s];
            if (slots[s] >= 0) m_units[s].vw = m_t.volume[slots[s]] * m_t.weight[slots[s]];
        }
    }

private:
    struct Unit {
        int32_t unit = -1;
        double vw = 1;
        std::array<double, 2> lam{};
    };
    ElasticTets m_t;
    std::vector<uint8_t> m_active; ///< per unit
    int m_count = 1;
    std::array<double, kMaxTetConstraints> m_alpha{};
    double m_restDensity = 0;
    std::vector<Unit> m_units;
};

// ---- strain limits (tets and triangles) ---------------------------------------------------------

/// Applies one scalar strain-limit update; returns the new multiplier.
template <int N>
double strainLimitUpdate(const ScalarStrainLimit& lim, double eps, const std::array<Vec3, N>& g,
                         const std::array<int32_t, N>& p, double measure, double lam, const SolveContext& ctx) {
    double den = 0;
    double w[N];
    for (int k = 0; k < N; ++k) {
        w[k] = particleInvMass(ctx.xw, p[k]);
        den += w[k] * g[k].squaredNorm();
    }
    const double t = lim.compliance / measure * ctx.h2inv;
    den += t;
    if (!(den > 0) || !std::isfinite(den)) return lam;
    const double C = eps - lim.s;
    double next = lam + (-C - t * lam) / den;
    if (lim.side > 0)
        next = std::min(next, 0.0);
    else if (lim.side < 0)
        next = std::max(next, 0.0);
    const double d = next - lam;
    if (d != 0)
        for (int k = 0; k < N; ++k)
            moveParticle(ctx.xw, p[k], (w[k] * d) * g[k]);
    return next;
}

double strainLimitEnergy(const ScalarStrainLimit& lim, double eps, double measure) {
    if (lim.compliance == 0) return 0;
    const double C = eps - lim.s;
    if ((lim.side > 0 && C <= 0) || (lim.side < 0 && C >= 0)) return 0;
    return measure * C * C / (2 * lim.compliance);
}

template <int N, class MatM> class StrainBlock final : public Block {
public:
    using Elem = std::array<int32_t, N>;
    StrainBlock(std::vector<Elem> elems, std::vector<MatM> dmInv, std::vector<double> measure,
                std::vector<ScalarStrainLimit> limits)
        : m_elems(std::move(elems)), m_dmInv(std::move(dmInv)), m_measure(std::move(measure)),
          m_limits(std::move(limits)), m_active(m_elems.size(), 1) {}
    bool setUnitActive(size_t u, bool active) override {
        m_active.at(u) = active ? 1 : 0;
        return true;
    }

    size_t unitCount() const override { return m_elems.size(); }
    int stage() const override { return 1; }
    int unitParticles(size_t u, int32_t* out) const override {
        std::copy_n(m_elems[u].begin(), N, out);
        return N;
    }
    void solve(size_t pb, size_t pe, const SolveContext& ctx) override {
        const size_t nl = m_limits.size();
        for (size_t s = 4 * pb; s < 4 * pe; ++s) {
            const int32_t u = m_slots[s];
            if (u < 0 || !m_active[u]) continue;
            double* lam = m_lam.data() + s * nl;
            if (ctx.first) std::fill_n(lam, nl, 0.0);
            const Elem& e = m_elems[u];
            for (size_t k = 0; k < nl; ++k) {
                std::array<Vec3, N> x, g;
                for (int i = 0; i < N; ++i)
                    x[i] = particlePosition(ctx.xw, e[i]);
                const double eps = strain(x, m_dmInv[u], m_limits[k].i, m_limits[k].j, &g);
                lam[k] = strainLimitUpdate<N>(m_limits[k], eps, g, e, m_measure[u], lam[k], ctx);
            }
        }
    }
    double energy(const double* xw, size_t unitBegin, size_t unitEnd) const override {
        double sum = 0;
        for (size_t u = unitBegin; u < unitEnd; ++u) {
            if (!m_active[u]) continue;
            std::array<Vec3, N> x;
            for (int i = 0; i < N; ++i)
                x[i] = particlePosition(xw, m_elems[u][i]);
            for (const auto& lim : m_limits)
                sum += strainLimitEnergy(lim, strain(x, m_dmInv[u], lim.i, lim.j, nullptr), m_measure[u]);
        }
        return sum;
    }

protected:
    void build(const std::vector<int32_t>& slots) override {
        m_slots = slots;
        m_lam.assign(slots.size() * m_limits.size(), 0.0);
    }

private:
    static double strain(const std::array<Vec3, N>& x, const MatM& M, int i, int j, std::array<Vec3, N>* g) {
        if constexpr (N == 4)
            return tetGreenStrain(x, M, i, j, g);
        else
            return triGreenStrain(x, M, i, j, g);
    }
    std::vector<Elem> m_elems;
    std::vector<MatM> m_dmInv;
    std::vector<double> m_measure;
    std::vector<ScalarStrainLimit> m_limits;
    std::vector<uint8_t> m_active; ///< per unit
    std::vector<int32_t> m_slots;
    std::vector<double> m_lam;
};

// ---- membrane -----------------------------------------------------------------------------------

class MembraneBlock final : public Block {
public:
    MembraneBlock(std::vector<Tri> tris, std::vector<Mat2> dmInv, std::vector<double> area, std::vector<double> k,
                  bool simd)
        : m_tris(std::move(tris)), m_dmInv(std::move(dmInv)), m_area(std::move(area)), m_k(std::move(k)),
          m_active(m_tris.size(), 1), m_simd(simd) {}
    bool setUnitActive(size_t u, bool active) override {
        m_active.at(u) = active ? 1 : 0;
        if (m_simd) m_packs[m_slotOf[u] / 4].active[m_slotOf[u] % 4] = active ? 1.0 : 0.0;
        return true;
    }
    bool setUnitRestInverse(size_t u, const double* m) override {
        m_dmInv.at(u) << m[0], m[1], m[2], m[3];
        if (m_simd)
            for (int e = 0; e < 4; ++e)
                m_packs[m_slotOf[u] / 4].m[e][m_slotOf[u] % 4] = m[e];
        return true;
    }

    size_t unitCount() const override { return m_tris.size(); }
    int unitParticles(size_t u, int32_t* out) const override {
        std::copy_n(m_tris[u].begin(), 3, out);
        return 3;
    }
    void solve(size_t pb, size_t pe, const SolveContext& ctx) override {
        if (m_simd) {
            if (pe > pb) membraneSolveAvx2(m_packs.data() + pb, pe - pb, {ctx.xw, ctx.h2inv, ctx.first ? 1 : 0});
            return;
        }
        // The three Green-strain constraints ε00, ε11, √2 ε01 of each triangle (triGreenStrain),
        // Gauss–Seidel one after the other; F = Ds M with Ds = [x1 − x0, x2 − x0] (3 × 2). The
        // (up to) four triangles of a pack share no particle (one colour), so they are worked on
        // side by side, constraint by constraint, on local copies of their vertices (written back
        // at the end): the same arithmetic per triangle as one after the other, with four
        // independent dependency chains in flight.
        static const double kSqrt2 = std::sqrt(2.0);
        static const int kEntry[3][2] = {{0, 0}, {1, 1}, {0, 1}};
        for (size_t q = pb; q < pe; ++q) {
            int n = 0;
            int32_t slot[4];
            for (size_t s = 4 * q; s < 4 * q + 4; ++s)
                if (m_slots[s] >= 0 && m_active[m_slots[s]]) slot[n++] = static_cast<int32_t>(s);
            double x[4][3][3], w[4][3], t[4];
            for (int l = 0; l < n; ++l) {
                const int32_t u = m_slots[slot[l]];
                if (ctx.first) std::fill_n(m_lam.data() + 3 * slot[l], 3, 0.0);
                t[l] = ctx.h2inv / (m_k[u] * m_area[u]);
                for (int i = 0; i < 3; ++i) {
                    const double* p = ctx.xw + 4 * static_cast<size_t>(m_tris[u][i]);
                    for (int r = 0; r < 3; ++r)
                        x[l][i][r] = p[r];
                    w[l][i] = p[3];
                }
            }
            for (int c = 0; c < 3; ++c) {
                const int ci = kEntry[c][0], cj = kEntry[c][1];
                const double scale = c == 2 ? kSqrt2 : 1.0;
                for (int l = 0; l < n; ++l) {
                    const Mat2& M = m_dmInv[m_slots[slot[l]]];
                    double* lam = m_lam.data() + 3 * slot[l];
                    double F[2][3]; // F[col][row]
                    for (int r = 0; r < 3; ++r) {
                        const double d1 = x[l][1][r] - x[l][0][r], d2 = x[l][2][r] - x[l][0][r];
                        F[0][r] = d1 * M(0, 0) + d2 * M(1, 0);
                        F[1][r] = d1 * M(0, 1) + d2 * M(1, 1);
                    }
                    const double C =
                        scale * 0.5 *
                        (F[ci][0] * F[cj][0] + F[ci][1] * F[cj][1] + F[ci][2] * F[cj][2] - (ci == cj ? 1.0 : 0.0));
                    double g[3][3];
                    for (int r = 0; r < 3; ++r) {
                        g[1][r] = scale * 0.5 * (M(0, ci) * F[cj][r] + M(0, cj) * F[ci][r]);
                        g[2][r] = scale * 0.5 * (M(1, ci) * F[cj][r] + M(1, cj) * F[ci][r]);
                        g[0][r] = -(g[1][r] + g[2][r]);
                    }
                    double den = t[l];
                    for (int i = 0; i < 3; ++i)
                        den += w[l][i] * (g[i][0] * g[i][0] + g[i][1] * g[i][1] + g[i][2] * g[i][2]);
                    if (!(den > 0) || !std::isfinite(den)) continue;
                    const double d = (-C - t[l] * lam[c]) / den;
                    lam[c] += d;
                    for (int i = 0; i < 3; ++i)
                        for (int r = 0; r < 3; ++r)
                            x[l][i][r] += w[l][i] * d * g[i][r];
                }
            }
            for (int l = 0; l < n; ++l) {
                const int32_t u = m_slots[slot[l]];
                for (int i = 0; i < 3; ++i) {
                    double* p = ctx.xw + 4 * static_cast<size_t>(m_tris[u][i]);
                    for (int r = 0; r < 3; ++r)
                        p[r] = x[l][i][r];
                }
            }
        }
    }
    double energy(const double* xw, size_t unitBegin, size_t unitEnd) const override {
        double sum = 0;
        for (size_t u = unitBegin; u < unitEnd; ++u) {
            if (!m_active[u]) continue;
            std::array<Vec3, 3> x;
            for (int i = 0; i < 3; ++i)
                x[i] = particlePosition(xw, m_tris[u][i]);
            const auto C = membraneConstraints(x, m_dmInv[u]);
            sum += 0.5 * m_k[u] * m_area[u] * (C[0] * C[0] + C[1] * C[1] + C[2] * C[2]);
        }
        return sum;
    }

protected:
    void build(const std::vector<int32_t>& slots) override {
        m_slots = slots;
        m_lam.assign(3 * slots.size(), 0.0);
        if (!m_simd) return;
        m_packs.assign(slots.size() / 4, MembranePack{});
        m_slotOf.assign(m_tris.size(), 0);
        for (size_t q = 0; q < m_packs.size(); ++q) {
            MembranePack& P = m_packs[q];
            const int32_t lane0 = slots[4 * q];
            for (int l = 0; l < 4; ++l) {
                const int32_t u = slots[4 * q + l];
                const int32_t src = u >= 0 ? u : lane0; // padding repeats lane 0 and moves nothing
                if (u >= 0) m_slotOf[u] = static_cast<int32_t>(4 * q + l);
                for (int i = 0; i < 3; ++i)
                    P.idx[i][l] = m_tris[src][i];
                const Mat2& M = m_dmInv[src];
                P.m[0][l] = M(0, 0);
                P.m[1][l] = M(0, 1);
                P.m[2][l] = M(1, 0);
                P.m[3][l] = M(1, 1);
                P.invKA[l] = 1.0 / (m_k[src] * m_area[src]);
                P.active[l] = u >= 0 && m_active[u] ? 1.0 : 0.0;
            }
        }
    }

private:
    std::vector<Tri> m_tris;
    std::vector<Mat2> m_dmInv;
    std::vector<double> m_area;
    std::vector<double> m_k;       ///< per unit, N/m
    std::vector<uint8_t> m_active; ///< per unit
    std::vector<int32_t> m_slots;
    std::vector<double> m_lam;
    // AVX2 path: the units in packs of four (slot order), and each unit's slot.
    bool m_simd = false;
    std::vector<MembranePack, AlignedAllocator<MembranePack, 64>> m_packs;
    std::vector<int32_t> m_slotOf;
};

// ---- coupling ties ------------------------------------------------------------------------------

class CouplingBlock final : public Block {
public:
    explicit CouplingBlock(std::vector<Tie> ties) : m_ties(std::move(ties)) {}

    size_t unitCount() const override { return m_ties.size(); }
    int stage() const override { return 2; }
    int unitParticles(size_t u, int32_t* out) const override {
        const Tie& t = m_ties[u];
        out[0] = t.p;
        for (int k = 0; k < t.n; ++k)
            out[k + 1] = t.t[k];
        return t.n + 1;
    }
    void solve(size_t pb, size_t pe, const SolveContext& ctx) override {
        for (size_t s = 4 * pb; s < 4 * pe; ++s) {
            const int32_t u = m_slots[s];
            if (u < 0) continue;
            Vec3& lam = m_lam[s];
            if (ctx.first) lam.setZero();
            const Tie& t = m_ties[u];
            const double wp = particleInvMass(ctx.xw, t.p);
            Vec3 target[4];
            double w[4];
            double den = wp;
            for (int k = 0; k < t.n; ++k) {
                target[k] = particlePosition(ctx.xw, t.t[k]);
                w[k] = particleInvMass(ctx.xw, t.t[k]);
                den += w[k] * t.b[k] * t.b[k];
            }
            const Vec3 C = couplingResidual(particlePosition(ctx.xw, t.p), target, t.b.data(), t.n);
            const double at = t.compliance * ctx.h2inv;
            den += at;
            if (!(den > 0) || !std::isfinite(den)) continue;
            const Vec3 d = (-C - at * lam) / den;
            lam += d;
            moveParticle(ctx.xw, t.p, wp * d);
            for (int k = 0; k < t.n; ++k)
                moveParticle(ctx.xw, t.t[k], (-w[k] * t.b[k]) * d);
        }
    }
    double energy(const double* xw, size_t unitBegin, size_t unitEnd) const override {
        double sum = 0;
        for (size_t u = unitBegin; u < unitEnd; ++u) {
            const Tie& t = m_ties[u];
            if (t.compliance == 0) continue;
            Vec3 target[4];
            for (int k = 0; k < t.n; ++k)
                target[k] = particlePosition(xw, t.t[k]);
            const Vec3 C = couplingResidual(particlePosition(xw, t.p), target, t.b.data(), t.n);
            sum += C.squaredNorm() / (2 * t.compliance);
        }
        return sum;
    }

protected:
    void build(const std::vector<int32_t>& slots) override {
        m_slots = slots;
        m_lam.assign(slots.size(), Vec3::Zero());
    }

private:
    std::vector<Tie> m_ties;
    std::vector<int32_t> m_slots;
    std::vector<Vec3> m_lam;
};

} // namespace

std::unique_ptr<Block> makeElasticBlock(ElasticTets tets, bool simd, bool* usesSimd) {
    if (usesSimd) *usesSimd = false;
    if (const auto* snh = dynamic_cast<const StableNeoHookeanModel*>(tets.model.get())) {
        const bool avx2 = simd && snhAvx2Available();
        if (usesSimd) *usesSimd = avx2;
        return std::make_unique<SnhBlock>(std::move(tets), *snh, avx2);
    }
    return std::make_unique<ModelBlock>(std::move(tets));
}

std::vector<ScalarStrainLimit> expandStrainLimits(const std::vector<StrainLimit>& limits) {
    std::vector<ScalarStrainLimit> out;
    for (const StrainLimit& l : limits) {
        if (l.lower == l.upper) {
            out.push_back({l.i, l.j, l.lower, 0, l.compliance});
            continue;
        }
        if (std::isfinite(l.upper)) out.push_back({l.i, l.j, l.upper, +1, l.compliance});
        if (std::isfinite(l.lower)) out.push_back({l.i, l.j, l.lower, -1, l.compliance});
    }
    return out;
}

std::unique_ptr<Block> makeTetStrainBlock(std::vector<Tet> tets, std::vector<Mat3> dmInv, std::vector<double> volume,
                                          std::vector<ScalarStrainLimit> limits) {
    return std::make_unique<StrainBlock<4, Mat3>>(std::move(tets), std::move(dmInv), std::move(volume),
                                                  std::move(limits));
}

std::unique_ptr<Block> makeTriStrainBlock(std::vector<Tri> tris, std::vector<Mat2> dmInv, std::vector<double> area,
                                          std::vector<ScalarStrainLimit> limits) {
    return std::make_unique<StrainBlock<3, Mat2>>(std::move(tris), std::move(dmInv), std::move(area),
                                                  std::move(limits));
}

std::unique_ptr<Block> makeMembraneBlock(std::vector<Tri> tris, std::vector<Mat2> dmInv, std::vector<double> area,
                                         std::vector<double> stiffness, bool simd) {
    return std::make_unique<MembraneBlock>(std::move(tris), std::move(dmInv), std::move(area), std::move(stiffness),
                                           simd && membraneAvx2Available());
}

std::unique_ptr<Block> makeCouplingBlock(std::vector<Tie> ties) {
    return std::make_unique<CouplingBlock>(std::move(ties));
}

} // namespace viscera::sim::detail
