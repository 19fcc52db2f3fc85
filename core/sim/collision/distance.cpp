#include "sim/collision/distance.hpp"

#include <algorithm>
#include <cmath>

namespace viscera::sim {

TrianglePoint closestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
    // Voronoi-region walk over the vertices, edges and face of the triangle.
    TrianglePoint r;
    const Vec3 ab = b - a, ac = c - a, ap = p - a;
    const double d1 = ab.dot(ap), d2 = ac.dot(ap);
    if (d1 <= 0 && d2 <= 0) return {a, Vec3(1, 0, 0)};
    const Vec3 bp = p - b;
    const double d3 = ab.dot(bp), d4 = ac.dot(bp);
    if (d3 >= 0 && d4 <= d3) return {b, Vec3(0, 1, 0)};
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0 && d1 - d3 > 0) {
        const double v = d1 / (d1 - d3);
        return {a + v * ab, Vec3(1 - v, v, 0)};
    }
    const Vec3 cp = p - c;
    const double d5 = ab.dot(cp), d6 = ac.dot(cp);
    if (d6 >= 0 && d5 <= d6) return {c, Vec3(0, 0, 1)};
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0 && d2 - d6 > 0) {
        const double w = d2 / (d2 - d6);
        return {a + w * ac, Vec3(1 - w, 0, w)};
    }
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0 && (d4 - d3) + (d5 - d6) > 0) {
        const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return {b + w * (c - b), Vec3(0, 1 - w, w)};
    }
    const double sum = va + vb + vc;
    if (sum > 0 && std::isfinite(sum)) {
        const double v = vb / sum, w = vc / sum;
        r.point = a + v * ab + w * ac;
        r.bary = Vec3(1 - v - w, v, w);
        return r;
    }
    // Degenerate triangle: nearest of the three edges.
    const Vec3 e[3][2] = {{a, b}, {b, c}, {c, a}};
    double best = 1e300;
    for (int k = 0; k < 3; ++k) {
        const double t = closestParameterOnSegment(p, e[k][0], e[k][1]);
        const Vec3 q = e[k][0] + t * (e[k][1] - e[k][0]);
        const double d = (q - p).squaredNorm();
        if (d < best) {
            best = d;
            r.point = q;
            r.bary.setZero();
            r.bary[k] = 1 - t;
            r.bary[(k + 1) % 3] = t;
        }
    }
    return r;
}

double closestParameterOnSegment(const Vec3& p, const Vec3& a, const Vec3& b) {
    const Vec3 d = b - a;
    const double dd = d.squaredNorm();
    if (!(dd > 0)) return 0;
    return std::clamp((p - a).dot(d) / dd, 0.0, 1.0);
}

SegmentPair closestPointsSegments(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1) {
    const Vec3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
    const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
    double s = 0, t = 0;
    if (a <= 0 && e <= 0) {
        s = t = 0;
    } else if (a <= 0) {
        t = std::clamp(f / e, 0.0, 1.0);
    } else {
        const double c = d1.dot(r);
        if (e <= 0) {
            s = std::clamp(-c / a, 0.0, 1.0);
        } else {
            const double b = d1.dot(d2), denom = a * e - b * b;
            s = denom > 1e-300 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
            t = (b * s + f) / e;
            if (t < 0) {
                t = 0;
                s = std::clamp(-c / a, 0.0, 1.0);
            } else if (t > 1) {
                t = 1;
                s = std::clamp((b - c) / a, 0.0, 1.0);
            }
        }
    }
    return {s, t, p0 + s * d1, q0 + t * d2};
}

SegmentTrianglePair closestPointsSegmentTriangle(const Vec3& s0, const Vec3& s1, const Vec3& a, const Vec3& b,
                                                 const Vec3& c) {
    SegmentTrianglePair best;
    best.distance = 1e300;
    auto consider = [&](const Vec3& onSeg, const TrianglePoint& onTri) {
        const double d = (onSeg - onTri.point).norm();
        if (d < best.distance) {
            best.distance = d;
            best.onSegment = onSeg;
            best.onTriangle = onTri;
        }
    };
    // Piercing: the segment crosses the triangle's plane inside the triangle.
    const Vec3 n = (b - a).cross(c - a);
    const double h0 = n.dot(s0 - a), h1 = n.dot(s1 - a);
    if (n.squaredNorm() > 0 && ((h0 <= 0 && h1 >= 0) || (h0 >= 0 && h1 <= 0)) && h0 != h1) {
        const double t = h0 / (h0 - h1);
        const Vec3 q = s0 + t * (s1 - s0);
        const TrianglePoint tp = closestPointOnTriangle(q, a, b, c);
        if ((tp.point - q).squaredNorm() <= 1e-24 * std::max(1.0, n.norm())) {
            best.onSegment = q;
            best.onTriangle = tp;
            best.distance = 0;
            return best;
        }
    }
    consider(s0, closestPointOnTriangle(s0, a, b, c));
    consider(s1, closestPointOnTriangle(s1, a, b, c));
    const Vec3 v[3] = {a, b, c};
    for (int k = 0; k < 3; ++k) {
        const SegmentPair sp = closestPointsSegments(s0, s1, v[k], v[(k + 1) % 3]);
        TrianglePoint tp;
        tp.point = sp.onQ;
        tp.bary.setZero();
        tp.bary[k] = 1 - sp.t;
        tp.bary[(k + 1) % 3] = sp.t;
        consider(sp.onP, tp);
    }
    return best;
}

} // namespace viscera::sim
