#include "render/thickness_bake.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>

namespace viscera::render {

TriangleBvh::TriangleBvh(const std::vector<Eigen::Vector3f>& positions,
                         const std::vector<std::array<uint32_t, 3>>& triangles)
    : m_v(positions), m_tris(triangles) {
    for (size_t t = 0; t < m_tris.size(); ++t)
        for (uint32_t i : m_tris[t])
            if (i >= m_v.size())
                throw std::invalid_argument("render::TriangleBvh: triangle " + std::to_string(t) +
                                            " references vertex " + std::to_string(i) + " (mesh has " +
                                            std::to_string(m_v.size()) + " vertices)");
    if (!m_tris.empty()) {
        m_nodes.reserve(2 * m_tris.size());
        build(0, uint32_t(m_tris.size()));
    }
}

int32_t TriangleBvh::build(uint32_t first, uint32_t count) {
    Node node;
    node.lo = Eigen::Vector3f::Constant(std::numeric_limits<float>::max());
    node.hi = -node.lo;
    Eigen::Vector3f clo = node.lo, chi = node.hi;
    for (uint32_t t = first; t < first + count; ++t) {
        Eigen::Vector3f c = Eigen::Vector3f::Zero();
        for (uint32_t i : m_tris[t]) {
            node.lo = node.lo.cwiseMin(m_v[i]);
            node.hi = node.hi.cwiseMax(m_v[i]);
            c += m_v[i] / 3.0f;
        }
        clo = clo.cwiseMin(c);
        chi = chi.cwiseMax(c);
    }
    const int32_t index = int32_t(m_nodes.size());
    m_nodes.push_back(node);
    if (count <= 4) {
        m_nodes[index].first = first;
        m_nodes[index].count = count;
        return index;
    }
    int axis = 0;
    (chi - clo).maxCoeff(&axis);
    auto centroid = [&](const std::array<uint32_t, 3>& t) {
        return m_v[t[0]][axis] + m_v[t[1]][axis] + m_v[t[2]][axis];
    };
    const uint32_t mid = first + count / 2;
    std::nth_element(m_tris.begin() + first, m_tris.begin() + mid, m_tris.begin() + first + count,
                     [&](const auto& a, const auto& b) { return centroid(a) < centroid(b); });
    const int32_t left = build(first, mid - first);
    const int32_t right = build(mid, first + count - mid);
    m_nodes[index].left = left;
    m_nodes[index].right = right;
    return index;
}

namespace {
bool hitBox(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi, const Eigen::Vector3f& o, const Eigen::Vector3f& inv,
            float tMin, float tMax) {
    for (int a = 0; a < 3; ++a) {
        float t0 = (lo[a] - o[a]) * inv[a], t1 = (hi[a] - o[a]) * inv[a];
        if (t0 > t1) std::swap(t0, t1);
        tMin = std::max(tMin, t0);
        tMax = std::min(tMax, t1);
        if (tMax < tMin) return false;
    }
    return true;
}
} // namespace

float TriangleBvh::raycast(const Eigen::Vector3f& o, const Eigen::Vector3f& d, float tMin, float tMax) const {
    if (m_nodes.empty()) return -1.0f;
    const Eigen::Vector3f inv(1.0f / d.x(), 1.0f / d.y(), 1.0f / d.z());
    float best = -1.0f;
    int32_t stack[64];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const Node& n = m_nodes[stack[--top]];
        if (!hitBox(n.lo, n.hi, o, inv, tMin, best > 0 ? best : tMax)) continue;
        if (n.left < 0) {
            for (uint32_t t = n.first; t < n.first + n.count; ++t) {
                // Möller–Trumbore, both sides.
                const Eigen::Vector3f& a = m_v[m_tris[t][0]];
                const Eigen::Vector3f e1 = m_v[m_tris[t][1]] - a, e2 = m_v[m_tris[t][2]] - a;
                const Eigen::Vector3f p = d.cross(e2);
                const float det = e1.dot(p);
                if (std::abs(det) < 1e-14f) continue;
                const float invDet = 1.0f / det;
                const Eigen::Vector3f s = o - a;
                const float u = s.dot(p) * invDet;
                if (u < 0.0f || u > 1.0f) continue;
                const Eigen::Vector3f q = s.cross(e1);
                const float v = d.dot(q) * invDet;
                if (v < 0.0f || u + v > 1.0f) continue;
                const float tt = e2.dot(q) * invDet;
                if (tt > tMin && tt <= tMax && (best < 0 || tt < best)) best = tt;
            }
        } else if (top < 62) {
            stack[top++] = n.left;
            stack[top++] = n.right;
        }
    }
    return best;
}

std::vector<float> bakeThickness(const std::vector<Eigen::Vector3f>& positions,
                                 const std::vector<Eigen::Vector3f>& normals, const TriangleBvh& target,
                                 const ThicknessBakeSettings& s) {
    if (normals.size() != positions.size())
        throw std::invalid_argument("render::bakeThickness(): " + std::to_string(normals.size()) + " normals for " +
                                    std::to_string(positions.size()) + " positions");
    const int rays = std::max(1, s.rays);
    // Cosine-weighted directions around +z (golden-angle spiral), rotated onto −n per vertex.
    std::vector<Eigen::Vector3f> local(rays);
    for (int r = 0; r < rays; ++r) {
        const float u = (float(r) + 0.5f) / float(rays);
        const float radius = std::sqrt(u) * 0.6f; // within 37° of −n: thickness along the normal
        const float phi = float(r) * 2.39996323f;
        local[r] = Eigen::Vector3f(radius * std::cos(phi), radius * std::sin(phi), std::sqrt(1.0f - radius * radius));
    }
    std::vector<float> out(positions.size(), s.maxThickness);
    for (size_t i = 0; i < positions.size(); ++i) {
        const Eigen::Vector3f n =
            normals[i].squaredNorm() > 0 ? Eigen::Vector3f(-normals[i].normalized()) : Eigen::Vector3f(0, 0, -1);
        const Eigen::Vector3f t = n.unitOrthogonal(), b = n.cross(t);
        const Eigen::Vector3f o = positions[i] + s.offset * n;
        double sum = 0;
        for (const Eigen::Vector3f& l : local) {
            const Eigen::Vector3f dir = (l.x() * t + l.y() * b + l.z() * n).normalized();
            const float hit = target.raycast(o, dir, 1e-6f, s.maxThickness);
            sum += hit > 0 ? hit : s.maxThickness;
        }
        out[i] = float(sum / rays);
    }
    return out;
}

} // namespace viscera::render
