#include "sim/suture/needle_curve.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace viscera::sim {

NeedleCurve NeedleCurve::straight(const Vec3& p, const Vec3& w) {
    NeedleCurve c;
    c.kind = Kind::Straight;
    c.p = p;
    c.w = w.normalized();
    return c;
}

NeedleCurve NeedleCurve::arc(const Vec3& centre, const Vec3& u, const Vec3& v, double radius) {
    NeedleCurve c;
    c.kind = Kind::Arc;
    c.p = centre;
    c.u = u.normalized();
    c.v = (v - v.dot(c.u) * c.u).normalized();
    c.r = radius;
    return c;
}

Vec3 NeedleCurve::point(double a) const {
    if (kind == Kind::Straight) return p + a * w;
    const double th = a / r;
    return p + r * std::cos(th) * u + r * std::sin(th) * v;
}

Vec3 NeedleCurve::tangent(double a) const {
    if (kind == Kind::Straight) return w;
    const double th = a / r;
    return -std::sin(th) * u + std::cos(th) * v;
}

int NeedleCurve::planeCrossings(const Vec3& n, double d, double a, double b, double* out, int cap) const {
    int k = 0;
    if (!(b > a)) return 0;
    if (kind == Kind::Straight) {
        const double den = n.dot(w);
        if (den == 0) return 0;
        const double s = (d - n.dot(p)) / den;
        if (s > a && s <= b && cap > 0) out[k++] = s;
        return k;
    }
    // r cos θ (û·n) + r sin θ (v̂·n) = d − p·n  →  A cos θ + B sin θ = C  [B eq. 3.22–3.25]
    const double A = r * u.dot(n), B = r * v.dot(n), C = d - p.dot(n);
    const double q = std::hypot(A, B);
    if (q == 0 || std::abs(C) > q) return 0;
    const double phi = std::atan2(B, A); // A cos θ + B sin θ = q cos(θ − φ)
    const double acos = std::acos(std::clamp(C / q, -1.0, 1.0));
    const double twoPi = 2 * std::numbers::pi;
    const double th0 = a / r, th1 = b / r;
    for (double base : {phi + acos, phi - acos}) {
        // All θ = base + 2πk in (th0, th1].
        double th = base + twoPi * std::ceil((th0 - base) / twoPi);
        if (th <= th0) th += twoPi;
        for (; th <= th1 && k < cap; th += twoPi)
            out[k++] = th * r;
        if (acos == 0) break; // tangent: one root
    }
    std::sort(out, out + k);
    return k;
}

double NeedleCurve::closestParameter(const Vec3& q, double a, double b) const {
    if (kind == Kind::Straight) return std::clamp((q - p).dot(w), a, b);
    const Vec3 d = q - p;
    const double th = std::atan2(d.dot(v), d.dot(u));
    // Candidate θ + 2πk nearest to the middle of [a, b], then clamp.
    const double mid = 0.5 * (a + b) / r;
    const double twoPi = 2 * std::numbers::pi;
    const double best = th + twoPi * std::round((mid - th) / twoPi);
    double s = std::clamp(best * r, a, b);
    // Compare with the ends (the clamped candidate may not be the nearest on a long interval).
    for (double e : {a, b})
        if ((point(e) - q).squaredNorm() < (point(s) - q).squaredNorm()) s = e;
    return s;
}

} // namespace viscera::sim
