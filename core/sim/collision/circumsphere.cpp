#include "sim/collision/circumsphere.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <utility>

namespace viscera::sim {

double CubicHermite::value(double x) const {
    if (x <= x0) return y0;
    if (x >= x1) return y1;
    const double L = x1 - x0, t = (x - x0) / L, t2 = t * t, t3 = t2 * t;
    const double h00 = 2 * t3 - 3 * t2 + 1, h01 = -2 * t3 + 3 * t2;
    const double h10 = t3 - 2 * t2 + t, h11 = t3 - t2;
    return y0 * h00 + y1 * h01 + L * (m0 * h10 + m1 * h11);
}

double CubicHermite::derivative(double x) const {
    if (x < x0 || x > x1) return 0;
    const double L = x1 - x0, t = (x - x0) / L, t2 = t * t;
    const double d00 = 6 * t2 - 6 * t, d01 = -6 * t2 + 6 * t;
    const double d10 = 3 * t2 - 4 * t + 1, d11 = 3 * t2 - 2 * t;
    return (y0 * d00 + y1 * d01) / L + m0 * d10 + m1 * d11;
}

CubicHermite curvatureHermite(double threshold) {
    if (!(threshold > 0) || !std::isfinite(threshold))
        throw std::invalid_argument("sim::curvatureHermite(): threshold h must be > 0 (1/m), got " +
                                    std::to_string(threshold));
    return CubicHermite{0.0, threshold, 1.0, 0.0, 0.0, 0.0};
}

std::string validate(const CircumsphereParams& p) {
    if (!(p.safeAngle > 0 && p.safeAngle < M_PI / 2)) return "safe angle must be in (0, pi/2) rad";
    if (!(p.scale >= 0) || !std::isfinite(p.scale)) return "scale phi must be finite and >= 0";
    if (!(p.curvatureThreshold > 0) || !std::isfinite(p.curvatureThreshold))
        return "curvature threshold h must be finite and > 0";
    if (!(p.energyScale >= 0) || !std::isfinite(p.energyScale)) return "energy scale must be finite and >= 0";
    if (!(p.updateThreshold >= 0)) return "update threshold delta must be >= 0";
    return {};
}

Circumcircle circumcircle(const Vec3& a, const Vec3& b, const Vec3& c) {
    Circumcircle cc;
    const Vec3 ab = b - a, ac = c - a, n = ab.cross(ac);
    const double n2 = n.squaredNorm();
    const double longest = std::max({ab.norm(), ac.norm(), (c - b).norm()});
    cc.area = 0.5 * std::sqrt(n2);
    if (n2 > 0) {
        cc.normal = n / std::sqrt(n2);
        // x_c = a + (|ac|² (n × ab)... standard closed form.
        const Vec3 off = (ac.squaredNorm() * n.cross(ab) + ab.squaredNorm() * ac.cross(n)) / (2 * n2);
        cc.radius = off.norm();
        cc.centre = a + off;
        cc.valid = std::isfinite(cc.radius) && cc.radius <= 4 * longest;
    }
    if (!cc.valid) {
        const Sphere s = boundingSphere(a, b, c);
        cc.centre = s.centre;
        cc.radius = s.radius;
        if (!(n2 > 0)) cc.normal = ab.squaredNorm() > 0 ? ab.unitOrthogonal() : Vec3::UnitZ();
    }
    return cc;
}

double circumsphereOffset(double circumradius, double h3, double energy, const CircumsphereParams& p) {
    return circumsphereOffset(circumradius, h3, energy, offsetPerRadius(p), p.energyScale);
}

double offsetPerRadius(const CircumsphereParams& p) {
    return p.scale / std::tan(p.safeAngle);
}

Sphere circumsphere(const Circumcircle& cc, double offset) {
    Sphere s;
    s.centre = cc.centre - offset * cc.normal;
    s.radius = std::sqrt(cc.radius * cc.radius + offset * offset);
    s.coneAxis = cc.normal;
    // The circumcircle lies at height `offset` above the centre: cos(half-angle) = offset / r.
    s.coneCos = s.radius > 0 ? offset / s.radius : 0.0;
    return s;
}

bool Sphere::inSafeCone(const Vec3& p) const {
    if (coneCos <= -1) return true;
    const Vec3 d = p - centre;
    const double len = d.norm();
    return len > 0 && d.dot(coneAxis) >= coneCos * len;
}

Sphere boundingSphere(const Vec3& a, const Vec3& b, const Vec3& c) {
    const Vec3 g = (a + b + c) / 3.0;
    return {g, std::sqrt(std::max({(a - g).squaredNorm(), (b - g).squaredNorm(), (c - g).squaredNorm()}))};
}

double triangleEnergyFactor(const std::array<Vec3, 3>& rest, const std::array<Vec3, 3>& current) {
    // Rest frame: e1 along the first edge, e2 in-plane orthogonal to it.
    const Vec3 r1 = rest[1] - rest[0], r2 = rest[2] - rest[0];
    const double l1 = r1.norm();
    const Vec3 n = r1.cross(r2);
    if (!(l1 > 0) || !(n.squaredNorm() > 0)) return 0;
    const Vec3 u = r1 / l1, w = n.normalized().cross(u);
    Eigen::Matrix2d Dm;
    Dm << l1, r2.dot(u), 0, r2.dot(w);
    Eigen::Matrix<double, 3, 2> Ds;
    Ds.col(0) = current[1] - current[0];
    Ds.col(1) = current[2] - current[0];
    const Eigen::Matrix<double, 3, 2> F = Ds * Dm.inverse();
    const Eigen::Matrix2d E = 0.5 * (F.transpose() * F - Eigen::Matrix2d::Identity());
    const double e = E.squaredNorm();
    // Saturated: a measure of the change of energy, bounded so that the sphere cannot grow
    // without limit with the deformation it causes.
    return std::isfinite(e) ? e / (1 + e) : 1.0;
}

SurfaceCurvature::SurfaceCurvature(size_t vertexCount, const std::vector<Tri>& triangles) : m_tris(triangles) {
    std::map<std::pair<int32_t, int32_t>, size_t> index;
    std::vector<int> uses;
    for (size_t t = 0; t < triangles.size(); ++t)
        for (int k = 0; k < 3; ++k) {
            int32_t a = triangles[t][k], b = triangles[t][(k + 1) % 3];
            if (a > b) std::swap(a, b);
            auto [it, fresh] = index.emplace(std::make_pair(a, b), m_edges.size());
            if (fresh) {
                m_edges.push_back({a, b, static_cast<int32_t>(t), -1});
                uses.push_back(1);
            } else {
                Edge& e = m_edges[it->second];
                if (++uses[it->second] == 2)
                    e.t1 = static_cast<int32_t>(t);
                else
                    e.t1 = -1; // non-manifold: no contribution
            }
        }
    for (size_t e = 0; e < m_edges.size(); ++e)
        if (uses[e] > 2) m_edges[e].t1 = -1;
    m_vEdgeStart.assign(vertexCount + 1, 0);
    m_vTriStart.assign(vertexCount + 1, 0);
    for (const Edge& e : m_edges) {
        ++m_vEdgeStart[e.v0 + 1];
        ++m_vEdgeStart[e.v1 + 1];
    }
    for (const Tri& t : triangles)
        for (int32_t v : t)
            ++m_vTriStart[v + 1];
    for (size_t v = 0; v < vertexCount; ++v) {
        m_vEdgeStart[v + 1] += m_vEdgeStart[v];
        m_vTriStart[v + 1] += m_vTriStart[v];
    }
    m_vEdges.resize(m_vEdgeStart.back());
    m_vTris.resize(m_vTriStart.back());
    std::vector<uint32_t> fe(m_vEdgeStart.begin(), m_vEdgeStart.end() - 1);
    std::vector<uint32_t> ft(m_vTriStart.begin(), m_vTriStart.end() - 1);
    for (size_t e = 0; e < m_edges.size(); ++e) {
        m_vEdges[fe[m_edges[e].v0]++] = static_cast<int32_t>(e);
        m_vEdges[fe[m_edges[e].v1]++] = static_cast<int32_t>(e);
    }
    for (size_t t = 0; t < triangles.size(); ++t)
        for (int32_t v : triangles[t])
            m_vTris[ft[v]++] = static_cast<int32_t>(t);
}

double SurfaceCurvature::vertexCurvature(int32_t v, const std::vector<Vec3>& x) const {
    if (v < 0 || static_cast<size_t>(v) + 1 >= m_vEdgeStart.size()) return 0;
    auto normalOf = [&](int32_t t) {
        const Tri& f = m_tris[t];
        return Vec3((x[f[1]] - x[f[0]]).cross(x[f[2]] - x[f[0]]));
    };
    double area = 0;
    for (uint32_t i = m_vTriStart[v]; i < m_vTriStart[v + 1]; ++i)
        area += 0.5 * normalOf(m_vTris[i]).norm();
    area /= 3.0;
    if (!(area > 0)) return 0;
    double integrated = 0;
    for (uint32_t i = m_vEdgeStart[v]; i < m_vEdgeStart[v + 1]; ++i) {
        const Edge& e = m_edges[m_vEdges[i]];
        if (e.t1 < 0) continue;
        const Vec3 n0 = normalOf(e.t0), n1 = normalOf(e.t1);
        const double beta = std::atan2(n0.cross(n1).norm(), n0.dot(n1));
        integrated += 0.5 * std::abs(beta) * (x[e.v1] - x[e.v0]).norm();
    }
    const double k = integrated / area;
    return std::isfinite(k) ? k : 0.0;
}

double SurfaceCurvature::triangleCurvature(int32_t t, const std::vector<Vec3>& x) const {
    const Tri& f = m_tris[t];
    return (vertexCurvature(f[0], x) + vertexCurvature(f[1], x) + vertexCurvature(f[2], x)) / 3.0;
}

} // namespace viscera::sim
