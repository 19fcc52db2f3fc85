#include "sim/mesh/tri_mesh.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <unordered_map>

namespace viscera::sim {

TriMesh TriMesh::fromArrays(std::vector<Vec3> positions, std::vector<Tri> triangles, const std::string& origin) {
    if (triangles.empty()) throw std::invalid_argument(origin + ": mesh has no triangles");
    for (size_t v = 0; v < positions.size(); ++v)
        if (!positions[v].allFinite())
            throw std::invalid_argument(origin + ": vertex " + std::to_string(v) + " has a non-finite coordinate");
    const auto n = static_cast<int64_t>(positions.size());
    for (size_t f = 0; f < triangles.size(); ++f) {
        const Tri& t = triangles[f];
        for (int k = 0; k < 3; ++k)
            if (t[k] < 0 || t[k] >= n)
                throw std::invalid_argument(origin + ": triangle " + std::to_string(f) + " references vertex " +
                                            std::to_string(t[k]) + " (mesh has " + std::to_string(n) + " vertices)");
        if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2])
            throw std::invalid_argument(origin + ": triangle " + std::to_string(f) + " repeats a vertex");
    }
    TriMesh m;
    m.m_positions = std::move(positions);
    m.m_triangles = std::move(triangles);
    return m;
}

Vec3 TriMesh::triangleNormal(size_t i) const {
    const Tri& t = m_triangles[i];
    Vec3 n = (m_positions[t[1]] - m_positions[t[0]]).cross(m_positions[t[2]] - m_positions[t[0]]);
    double len = n.norm();
    return len > 0 ? Vec3(n / len) : Vec3::Zero();
}

double TriMesh::area() const {
    double a = 0;
    for (const Tri& t : m_triangles)
        a += 0.5 * (m_positions[t[1]] - m_positions[t[0]]).cross(m_positions[t[2]] - m_positions[t[0]]).norm();
    return a;
}

double TriMesh::signedVolume() const {
    double v = 0;
    for (const Tri& t : m_triangles)
        v += m_positions[t[0]].dot(m_positions[t[1]].cross(m_positions[t[2]])) / 6.0;
    return v;
}

bool TriMesh::isClosedOriented() const {
    // Every directed edge must appear once and its reverse once.
    std::unordered_map<uint64_t, int> directed;
    directed.reserve(m_triangles.size() * 3);
    auto key = [](int32_t a, int32_t b) {
        return (static_cast<uint64_t>(static_cast<uint32_t>(a)) << 32) | static_cast<uint32_t>(b);
    };
    for (const Tri& t : m_triangles)
        for (int k = 0; k < 3; ++k)
            if (++directed[key(t[k], t[(k + 1) % 3])] > 1) return false;
    for (const auto& [k, count] : directed) {
        int32_t a = static_cast<int32_t>(k >> 32), b = static_cast<int32_t>(k & 0xffffffffu);
        if (!directed.count(key(b, a))) return false;
    }
    return true;
}

std::array<Vec3, 2> TriMesh::bounds() const {
    Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
    Vec3 hi = -lo;
    for (const Vec3& p : m_positions) {
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
    }
    return {lo, hi};
}

Eigen::Vector3d barycentric(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& p) {
    // Ratios of sub-triangle areas, signed against the triangle normal (projection onto its plane).
    Vec3 n = (b - a).cross(c - a);
    double nn = n.squaredNorm();
    if (nn == 0) return Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
    double wa = (c - b).cross(p - b).dot(n) / nn;
    double wb = (a - c).cross(p - c).dot(n) / nn;
    return {wa, wb, 1.0 - wa - wb};
}

} // namespace viscera::sim
