#include "sim/material/valanis_landel.hpp"

#include "sim/util/error.hpp"
#include "sim/util/format.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>

namespace viscera::sim {

namespace {

double curveValue(const std::optional<MonotoneCurve>& c, double x) {
    return c ? c->value(x) : 0.0;
}
double curveSlope(const std::optional<MonotoneCurve>& c, double x) {
    return c ? c->derivative(x) : 0.0;
}

/// Largest root of β³ − 3β = 2r for r in [0, 1], β = 2 cos(acos(r)/3) in [√3, 2]: its degree-17
/// Chebyshev interpolant in t = 2r − 1, in monomial form (coefficient sum 2, so no cancellation)
/// evaluated in Estrin's order. The root is analytic on [0, 1] (its branch point is r = −1);
/// error below 7e-16 (3 ulp) in double, so p β has the accuracy of the cubic's coefficients.
double largestDepressedCubicRoot(double r) {
    constexpr double c[18] = {1.8793852415718166,      0.13164361454489953,    -0.012862827975309531,
                              0.002213309911670022,    -0.0004672905593236235, 0.00010982883739243108,
                              -2.7582551520811382e-05, 7.2465777463647e-06,    -1.967100732486947e-06,
                              5.473607998941967e-07,   -1.552200855299401e-07, 4.473191705071068e-08,
                              -1.3186905785460066e-08, 3.8929562920498784e-09, -1.032444158601723e-09,
                              3.08997060034581e-10,    -1.610559523763899e-10, 4.9182677563478205e-11};
    const double t = 2.0 * r - 1.0;
    const double t2 = t * t, t4 = t2 * t2, t8 = t4 * t4, t16 = t8 * t8;
    const auto pair = [&](int i) { return c[i] + c[i + 1] * t; };
    const double q0 = pair(0) + pair(2) * t2, q1 = pair(4) + pair(6) * t2;
    const double q2 = pair(8) + pair(10) * t2, q3 = pair(12) + pair(14) * t2;
    return ((q0 + q1 * t4) + (q2 + q3 * t4) * t8) + pair(16) * t16;
}

/// A 3-vector as three scalars: the decomposition below is a long scalar dependency chain, and
/// plain scalar code compiles to about 30 % fewer instructions than Eigen's 3-vectors (no lane
/// shuffles), with a shorter critical path.
struct V3 {
    double x, y, z;
};
V3 operator+(V3 a, V3 b) {
    return {a.x + b.x, a.y + b.y, a.z + b.z};
}
V3 operator-(V3 a, V3 b) {
    return {a.x - b.x, a.y - b.y, a.z - b.z};
}
V3 operator*(double s, V3 a) {
    return {s * a.x, s * a.y, s * a.z};
}
double dot(V3 a, V3 b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
V3 cross(V3 a, V3 b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
V3 column(const Mat3& M, int j) {
    return {M(0, j), M(1, j), M(2, j)};
}
void setColumn(Mat3& M, int j, V3 v) {
    M(0, j) = v.x;
    M(1, j) = v.y;
    M(2, j) = v.z;
}

/// 2^-k with k = floor(log2(v) / 2) for a positive normal v, so that v 4^-k lies in [1, 4):
/// exact rescaling by exponent arithmetic (no sqrt, no division).
double inverseSqrtPowerOfTwo(double v) {
    const std::int64_t e = static_cast<std::int64_t>(std::bit_cast<std::uint64_t>(v) >> 52) - 1023;
    return std::bit_cast<double>(static_cast<std::uint64_t>(1023 - (e >> 1)) << 52);
}

/// Eigenvectors of the symmetric A = [a00 a01 a02; a01 a11 a12; a02 a12 a22] (entries between
/// ~2^-120 and ~2^121, see signedSvdScaled()), as columns c_i of positive lengths 1/k_i, ordered
/// by decreasing eigenvalue (up to rounding at ties) and right-handed.
struct EigenFrame {
    V3 c[3];
    double k[3];
};
[[gnu::always_inline]] inline EigenFrame eigenFrame(double a00, double a11, double a22, double a01, double a02,
                                                    double a12) {
    const EigenFrame identity{{{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}}, {1.0, 1.0, 1.0}};
    // B = A − qI: eigenvalues q + p β with p² = tr(B²)/6 (the spread) and β³ − 3β = 2r,
    // r = det(B) / (2p³) in [−1, 1].
    const double q = (a00 + a11 + a22) * (1.0 / 3.0);
    const double b00 = a00 - q, b11 = a11 - q, b22 = a22 - q;
    const double p2 =
        (b00 * b00 + b11 * b11 + b22 * b22) * (1.0 / 6.0) + (a01 * a01 + a02 * a02 + a12 * a12) * (1.0 / 3.0);
    // Isotropic to far below rounding (spread < 1e-30 q): every basis diagonalizes A.
    if (!(p2 > 1e-60 * q * q)) return identity;
    const double p = std::sqrt(p2);
    const double detB = b00 * (b11 * b22 - a12 * a12) - a01 * (a01 * b22 - a12 * a02) + a02 * (a01 * a12 - b11 * a02);
    const double r = std::clamp(detB / (2.0 * p2 * p2) * p, -1.0, 1.0);
    // The extreme root on the side of r (largest for r ≥ 0, smallest for r < 0) has
    // |β| ≥ √3 while the other two lie in [−√3, 1] (resp. [−1, √3]): a simple eigenvalue,
    // at least √3 p from the others, whatever their own gap.
    const bool largest = r >= 0;
    const double pb = p * largestDepressedCubicRoot(std::abs(r));
    const double shift = largest ? pb : -pb;
    // Its eigenvector x spans the null space of B − shift I (rank 2): the largest cross
    // product of two rows (the largest column of the adjugate). Branches, not selects, here
    // and below: the chain is latency-bound and a predicted branch costs nothing.
    const V3 r0{b00 - shift, a01, a02}, r1{a01, b11 - shift, a12}, r2{a02, a12, b22 - shift};
    const V3 x01 = cross(r0, r1), x02 = cross(r0, r2), x12 = cross(r1, r2);
    const double n01 = dot(x01, x01), n02 = dot(x02, x02), n12 = dot(x12, x12);
    V3 x = x12;
    double nmax = n12;
    if (n01 >= n02 && n01 >= n12) {
        x = x01;
        nmax = n01;
    } else if (n02 >= n12) {
        x = x02;
        nmax = n02;
    }
    // The isolated eigenvalue makes B − shift I rank 2, so this only guards against rounding.
    if (!(nmax >= std::numeric_limits<double>::min())) [[unlikely]]
        return identity;
    x = inverseSqrtPowerOfTwo(nmax) * x; // exact; |x|² in [1, 4)
    const double nx = dot(x, x), len = std::sqrt(nx);
    // Orthogonal complement, unnormalized: w1 = x × e_j with |x_j| smallest (|w1|² ≥ 2|x|²/3)
    // and w2 = x × w1 (|w2|² = |x|² |w1|²); det[x, w1, w2] > 0.
    const double ax = std::abs(x.x), ay = std::abs(x.y), az = std::abs(x.z);
    V3 w1{x.y, -x.x, 0.0};
    if (ax <= ay && ax <= az)
        w1 = V3{0.0, x.z, -x.y};
    else if (ay <= az)
        w1 = V3{-x.z, 0.0, x.x};
    const V3 w2 = cross(x, w1);
    // The other two eigenvectors: the exact rotation diagonalizing the 2×2 block of B in the
    // orthonormal basis (w1/|w1|, w2/|w2|) (robust for equal or nearly equal eigenvalues,
    // where cross products are not). Its entries times |w2|² = |x|² |w1|² are
    // (w1ᵀBw1 |x|², w1ᵀBw2 |x|, w2ᵀBw2): (h, m) below is (half-difference, off-diagonal)
    // times |w2|², which leaves the rotation unchanged.
    const V3 Bw1{b00 * w1.x + a01 * w1.y + a02 * w1.z, a01 * w1.x + b11 * w1.y + a12 * w1.z,
                 a02 * w1.x + a12 * w1.y + b22 * w1.z};
    const V3 Bw2{b00 * w2.x + a01 * w2.y + a02 * w2.z, a01 * w2.x + b11 * w2.y + a12 * w2.z,
                 a02 * w2.x + a12 * w2.y + b22 * w2.z};
    const double h = 0.5 * (dot(w1, Bw1) * nx - dot(w2, Bw2));
    const double m = dot(w1, Bw2) * len;
    const double rr = std::sqrt(h * h + m * m);
    const double big = rr + std::abs(h);
    double norm2 = 2.0 * rr * big; // |(ca, sa)|²
    // (ca, sa) ∝ eigenvector of the larger eigenvalue: (big, m) for h ≥ 0, else (m, big).
    double ca = h >= 0 ? big : m, sa = h >= 0 ? m : big; // compiled to compare masks
    if (!(norm2 > 0)) {                                  // equal eigenvalues: any rotation
        ca = 1.0;
        sa = 0.0;
        norm2 = 1.0;
    }
    const V3 lw1 = len * w1;
    const V3 e1 = ca * lw1 + sa * w2, e2 = ca * w2 - sa * lw1; // |e|² = norm2 |w2|²
    const double kx = 1.0 / len, ke = 1.0 / std::sqrt(norm2 * nx * dot(w1, w1));
    // Decreasing eigenvalues, right-handed: det[x, e1, e2] = det[e1, e2, x] > 0.
    if (largest) return {{x, e1, e2}, {kx, ke, ke}};
    return {{e1, e2, x}, {ke, ke, kx}};
}

/// signedSvd() for max|F_ij| in [2^-60, 2^60], so that A = FᵀF, the cubic's coefficients and
/// the cross products below stay far from overflow and underflow.
///
/// Latency-minded (the XPBD loop waits on it): no loop, few divisions and square roots in
/// sequence, and eigenvectors carried unnormalized (with their inverse lengths k_i) as long as
/// possible, since U = F V diag(1/σ) does not depend on their lengths.
[[gnu::always_inline]] inline SignedSvd signedSvdScaled(const Mat3& F) {
    const V3 f0 = column(F, 0), f1 = column(F, 1), f2 = column(F, 2);
    const EigenFrame e = eigenFrame(dot(f0, f0), dot(f1, f1), dot(f2, f2), dot(f0, f1), dot(f0, f2), dot(f1, f2));
    const V3 c0 = e.c[0], c1 = e.c[1], c2 = e.c[2];
    const double k0 = e.k[0], k1 = e.k[1], k2 = e.k[2];
    SignedSvd out;
    setColumn(out.V, 0, k0 * c0);
    setColumn(out.V, 1, k1 * c1);
    setColumn(out.V, 2, k2 * c2);
    const auto times = [&](V3 c) { return c.x * f0 + c.y * f1 + c.z * f2; };
    const V3 g0 = times(c0), g1 = times(c1), g2 = times(c2); // = U diag(σ) diag(1/k)
    const double l0 = std::sqrt(dot(g0, g0)), l1 = std::sqrt(dot(g1, g1));
    out.sigma(0) = l0 * k0; // ≥ max|F_ij| / √3 > 0 up to rounding
    if (l1 * k1 > 0.1 * out.sigma(0)) [[likely]] {
        // F v1 ⊥ F v0 within ~1e-16 σ1² (the eigen-residual): u1 = F v1 / σ2 is orthogonal to
        // u0 within ~1e-16 σ1/σ2 < 1e-15.
        const double i0 = 1.0 / l0, i1 = 1.0 / l1;
        const V3 u0 = i0 * g0, u1 = i1 * g1;
        setColumn(out.U, 0, u0);
        setColumn(out.U, 1, u1);
        setColumn(out.U, 2, cross(u0, u1));
        out.sigma(1) = l1 * k1;
        // σ3 = u3 · F v3 = det[g0, g1, g2] k2 / (l0 l1): the triple product does not wait for U.
        out.sigma(2) = dot(cross(g0, g1), g2) * (k2 * i0 * i1); // signed: det U = det V = +1
    } else {
        // Strongly anisotropic (σ2 < σ1/10, rank ≤ 1 included): FᵀF resolves the two small
        // singular vectors only to ~1e-16 (σ1/σ2)². Re-split their plane from F itself: remove
        // the u1 components of F v2, F v3 (Gram–Schmidt, twice) and make them orthogonal with one
        // Jacobi rotation of (v2, v3), as a one-sided Jacobi SVD would (~1e-16 σ1/σ2).
        const V3 u0 = (1.0 / l0) * g0;
        V3 v1 = k1 * c1, v2 = k2 * c2;
        V3 h1 = times(v1), h2 = times(v2);
        for (int pass = 0; pass < 2; ++pass) {
            h1 = h1 - dot(u0, h1) * u0;
            h2 = h2 - dot(u0, h2) * u0;
        }
        const double a = dot(h1, h1), b = dot(h2, h2), g = dot(h1, h2);
        if (g != 0) {
            // t = tan θ of the rotation making c h1 − s h2 ⊥ s h1 + c h2 (the smaller root).
            const double zeta = (b - a) / (2.0 * g);
            const double t = std::copysign(1.0, zeta) / (std::abs(zeta) + std::sqrt(1.0 + zeta * zeta));
            const double c = 1.0 / std::sqrt(1.0 + t * t), sn = c * t;
            const V3 h1r = c * h1 - sn * h2, v1r = c * v1 - sn * v2;
            h2 = sn * h1 + c * h2;
            v2 = sn * v1 + c * v2;
            h1 = h1r;
            v1 = v1r;
        }
        if (dot(h2, h2) > dot(h1, h1)) { // larger first; a quarter turn keeps det V = +1
            std::swap(h1, h2);
            std::swap(v1, v2);
            h2 = -1.0 * h2;
            v2 = -1.0 * v2;
        }
        const double n1 = std::sqrt(dot(h1, h1));
        V3 u1;
        if (n1 > 1e-200 * l0) {
            u1 = (1.0 / n1) * h1;
        } else { // rank 1: any unit vector orthogonal to u0
            const double ax = std::abs(u0.x), ay = std::abs(u0.y), az = std::abs(u0.z);
            const V3 axis = ax <= ay && ax <= az ? V3{1.0, 0.0, 0.0} : ay <= az ? V3{0.0, 1.0, 0.0} : V3{0.0, 0.0, 1.0};
            const V3 t = cross(u0, axis);
            u1 = (1.0 / std::sqrt(dot(t, t))) * t;
        }
        const V3 u2 = cross(u0, u1);
        setColumn(out.U, 0, u0);
        setColumn(out.U, 1, u1);
        setColumn(out.U, 2, u2);
        setColumn(out.V, 1, v1);
        setColumn(out.V, 2, v2);
        out.sigma(1) = n1;
        out.sigma(2) = dot(u2, h2); // signed: det U = det V = +1
    }
    // Ties broken by rounding can leave the order one ulp off: restore σ1 ≥ σ2 ≥ |σ3|.
    const auto swapColumns = [&](int i, int j) {
        std::swap(out.sigma(i), out.sigma(j));
        out.U.col(i).swap(out.U.col(j));
        out.V.col(i).swap(out.V.col(j));
        out.U.col(j) *= -1.0; // both determinants back to +1, U diag(σ) Vᵀ unchanged
        out.V.col(j) *= -1.0;
    };
    if (out.sigma(1) > out.sigma(0)) [[unlikely]]
        swapColumns(0, 1);
    if (std::abs(out.sigma(2)) > out.sigma(1)) [[unlikely]] {
        swapColumns(1, 2);
        if (out.sigma(1) > out.sigma(0)) swapColumns(0, 1);
        for (int i = 0; i < 2; ++i)
            if (out.sigma(i) < 0) { // move the sign to the smallest stretch
                out.sigma(i) = -out.sigma(i);
                out.U.col(i) *= -1.0;
                out.sigma(2) = -out.sigma(2);
                out.U.col(2) *= -1.0;
            }
    }
    return out;
}

/// signedSvd() outside [2^-60, 2^60] (cold): zero, non-finite, or rescaled by a power of two.
[[gnu::noinline]] SignedSvd signedSvdRescaled(const Mat3& F, double maxAbs) {
    if (maxAbs == 0) return {Mat3::Identity(), Eigen::Vector3d::Zero(), Mat3::Identity()};
    if (!std::isfinite(maxAbs)) {
        const double nan = std::numeric_limits<double>::quiet_NaN();
        return {Mat3::Constant(nan), Eigen::Vector3d::Constant(nan), Mat3::Constant(nan)};
    }
    // Power-of-two scaling is exact: max|F_ij| moves into [1, 2).
    const int e = std::ilogb(maxAbs);
    SignedSvd out = signedSvdScaled(F * std::ldexp(1.0, -e));
    out.sigma *= std::ldexp(1.0, e);
    return out;
}

/// signedSvd(), inlined into its callers in this file (psiAndStress keeps U, σ, V in registers).
[[gnu::always_inline]] inline SignedSvd decompose(const Mat3& F) {
    const double maxAbs = F.cwiseAbs().maxCoeff();
    if (maxAbs >= 0x1p-60 && maxAbs <= 0x1p60) [[likely]]
        return signedSvdScaled(F);
    return signedSvdRescaled(F, maxAbs);
}

} // namespace

SignedSvd signedSvd(const Mat3& F) {
    return decompose(F);
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
        return std::string(label) + (c ? "(1)=" + formatNumber(v, 12) : " absent");
    };
    const std::string values = describe("f'", f, f1) + ", " + describe("g'", g, g1) + ", " + describe("h'", h, h1);
    const double rest = f1 + 2.0 * g1 + h1;
    const double scale = std::max({std::abs(f1), std::abs(2.0 * g1), std::abs(h1), std::abs(m_restStiffness)});
    if (!(std::abs(rest) <= kRestStressTolerance * scale))
        throw InputError(where + ": stress at rest f'(1) + 2 g'(1) + h'(1) = " + formatNumber(rest, 12) +
                         " Pa is not zero (" + values + ")");
    if (!(m_restStiffness > 0))
        throw InputError(where + ": stiffness at rest f''(1) + 2 g''(1) + h''(1) = " +
                         formatNumber(m_restStiffness, 12) + " Pa is not positive (" + values + ")");
    if (!(m_shearModulus > 0))
        throw InputError(where + ": shear modulus at rest (f''(1) + g''(1) - g'(1) - h'(1))/2 = " +
                         formatNumber(m_shearModulus, 12) + " Pa is not positive (" + values + ")");
}

inline double ValanisLandelDensity::principal(const Eigen::Vector3d& s, const MonotoneCurve::Sample& hJ,
                                              Eigen::Vector3d* d) const {
    const auto& c = m_curves;
    double e = 0;
    Eigen::Vector3d dpsi = Eigen::Vector3d::Zero();
    if (c.fPrime) {
        const auto f0 = c.fPrime->sample(s(0)), f1 = c.fPrime->sample(s(1)), f2 = c.fPrime->sample(s(2));
        e += f0.integralFromRest + f1.integralFromRest + f2.integralFromRest;
        dpsi = Eigen::Vector3d(f0.value, f1.value, f2.value);
    }
    if (c.gPrime) {
        const auto g01 = c.gPrime->sample(s(0) * s(1)), g12 = c.gPrime->sample(s(1) * s(2)),
                   g02 = c.gPrime->sample(s(0) * s(2));
        e += g01.integralFromRest + g12.integralFromRest + g02.integralFromRest;
        dpsi(0) += s(1) * g01.value + s(2) * g02.value;
        dpsi(1) += s(0) * g01.value + s(2) * g12.value;
        dpsi(2) += s(0) * g02.value + s(1) * g12.value;
    }
    if (c.hPrime) {
        e += hJ.integralFromRest;
        dpsi(0) += s(1) * s(2) * hJ.value;
        dpsi(1) += s(0) * s(2) * hJ.value;
        dpsi(2) += s(0) * s(1) * hJ.value;
    }
    if (d) *d = dpsi;
    return e;
}

double ValanisLandelDensity::psiPrincipal(const Eigen::Vector3d& s) const {
    const auto& h = m_curves.hPrime;
    return principal(s, h ? h->sample(s.prod()) : MonotoneCurve::Sample{}, nullptr);
}

Eigen::Vector3d ValanisLandelDensity::stressPrincipal(const Eigen::Vector3d& s) const {
    const auto& h = m_curves.hPrime;
    Eigen::Vector3d d;
    principal(s, h ? h->sample(s.prod()) : MonotoneCurve::Sample{}, &d);
    return d;
}

double ValanisLandelDensity::evaluate(const Mat3& F, Mat3* P) const {
    // The h′ segment lookup goes first in program order, from det F, so that it runs alongside
    // the SVD's dependency chain; the value is then taken at J = σ1 σ2 σ3, which for an
    // ill-conditioned F is more accurate than det F (and almost always in the same segment).
    const auto& h = m_curves.hPrime;
    const std::size_t hSegment = h ? h->locate(F.determinant()) : 0;
    const SignedSvd svd = decompose(F);
    const auto hJ = h ? h->sampleFrom(svd.sigma.prod(), hSegment) : MonotoneCurve::Sample{};
    if (!P) return principal(svd.sigma, hJ, nullptr);
    Eigen::Vector3d d;
    const double e = principal(svd.sigma, hJ, &d);
    P->noalias() = (svd.U * d.asDiagonal()) * svd.V.transpose();
    return e;
}

double ValanisLandelDensity::psi(const Mat3& F) const {
    return evaluate(F, nullptr);
}

Mat3 ValanisLandelDensity::stress(const Mat3& F) const {
    Mat3 P;
    evaluate(F, &P);
    return P;
}

double ValanisLandelDensity::psiAndStress(const Mat3& F, Mat3& P) const {
    return evaluate(F, &P);
}

ValanisLandelCurves neoHookeanCurves(double mu, double lambda, const NeoHookeanCurveOptions& options) {
    if (!(mu > 0) || !std::isfinite(mu) || !(lambda >= 0) || !std::isfinite(lambda))
        throw std::invalid_argument("sim::neoHookeanCurves(): mu " + formatNumber(mu, 12) + " and lambda " +
                                    formatNumber(lambda, 12) + " must be finite with mu > 0, lambda >= 0");
    ValanisLandelCurves curves;
    curves.fPrime = MonotoneCurve::fit("f'", [mu](double x) { return mu * x; },
                                       {.xmin = options.stretchMin,
                                        .xmax = options.stretchMax,
                                        .count = options.stretchCount,
                                        .spacing = CurveSpacing::Geometric,
                                        .shape = CurveShape::StrictlyIncreasing});
    // h′ peaks at J = exp(1 + μ/λ) (h″ = (μ + λ(1 − log J))/J²).
    const double peak = lambda > 0 ? std::exp(1.0 + mu / lambda) : std::numeric_limits<double>::infinity();
    curves.hPrime = MonotoneCurve::fit(
        "h'", [mu, lambda](double J) { return (lambda * std::log(J) - mu) / J; },
        {.xmin = options.volumeMin,
         .xmax = options.volumeMax,
         .count = options.volumeCount,
         .spacing = CurveSpacing::Geometric,
         .shape = options.volumeMax < peak ? CurveShape::StrictlyIncreasing : CurveShape::Unconstrained});
    return curves;
}

} // namespace viscera::sim
