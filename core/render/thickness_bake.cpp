#include "render/thickness_bake.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>
#include <utility>

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

Image bakeThicknessTexture(const std::vector<Eigen::Vector3f>& positions, const std::vector<Eigen::Vector3f>& normals,
                           const std::vector<std::array<uint32_t, 3>>& triangles,
                           const std::vector<Eigen::Vector2f>& uv, const TriangleBvh& target, int size, float range,
                           const ThicknessBakeSettings& settings, size_t* covered) {
    const std::string fn = "render::bakeThicknessTexture(): ";
    if (uv.size() != positions.size() || normals.size() != positions.size())
        throw std::invalid_argument(fn + std::to_string(uv.size()) + " uv and " + std::to_string(normals.size()) +
                                    " normals for " + std::to_string(positions.size()) + " positions");
    if (size < 1 || size > 4096) throw std::invalid_argument(fn + "size " + std::to_string(size) + " not in [1, 4096]");
    if (!(range > 0)) throw std::invalid_argument(fn + "range must be positive");
    // texel (x, y) ↔ uv ((x + 0.5) / size, 1 − (y + 0.5) / size)
    std::vector<int32_t> owner(size_t(size) * size, -1);
    std::vector<Eigen::Vector3f> points, pointNormals;
    for (const auto& t : triangles) {
        for (uint32_t v : t)
            if (v >= positions.size()) throw std::invalid_argument(fn + "index " + std::to_string(v) + " out of range");
        Eigen::Vector2f a = uv[t[0]] * float(size), b = uv[t[1]] * float(size), c = uv[t[2]] * float(size);
        for (Eigen::Vector2f* q : {&a, &b, &c})
            q->y() = float(size) - q->y(); // rows from the top
        const Eigen::Vector2f lo = a.cwiseMin(b).cwiseMin(c), hi = a.cwiseMax(b).cwiseMax(c);
        if ((hi - lo).maxCoeff() > 0.5f * float(size) || !lo.allFinite() || !hi.allFinite()) continue;
        const float area = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
        if (std::abs(area) < 1e-12f) continue;
        const int x0 = std::max(0, int(std::floor(lo.x()))), x1 = std::min(size - 1, int(std::ceil(hi.x())));
        const int y0 = std::max(0, int(std::floor(lo.y()))), y1 = std::min(size - 1, int(std::ceil(hi.y())));
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x) {
                const Eigen::Vector2f p(float(x) + 0.5f, float(y) + 0.5f);
                const float w1 = ((p - a).x() * (c - a).y() - (p - a).y() * (c - a).x()) / area;
                const float w2 = ((b - a).x() * (p - a).y() - (b - a).y() * (p - a).x()) / area;
                const float w0 = 1.0f - w1 - w2;
                constexpr float eps = -1e-5f;
                if (w0 < eps || w1 < eps || w2 < eps) continue;
                int32_t& o = owner[size_t(y) * size + x];
                if (o >= 0) continue; // the first triangle over a texel keeps it
                o = int32_t(points.size());
                points.push_back(w0 * positions[t[0]] + w1 * positions[t[1]] + w2 * positions[t[2]]);
                const Eigen::Vector3f n = w0 * normals[t[0]] + w1 * normals[t[1]] + w2 * normals[t[2]];
                pointNormals.push_back(n.squaredNorm() > 0 ? Eigen::Vector3f(n.normalized()) : n);
            }
    }
    if (covered) *covered = points.size();
    const std::vector<float> thick = bakeThickness(points, pointNormals, target, settings);
    std::vector<float> value(owner.size(), -1.0f);
    for (size_t i = 0; i < owner.size(); ++i)
        if (owner[i] >= 0) value[i] = thick[size_t(owner[i])];
    for (int pass = 0; pass < 4; ++pass) { // grow the covered texels by one ring per pass
        std::vector<float> next = value;
        for (int y = 0; y < size; ++y)
            for (int x = 0; x < size; ++x) {
                if (value[size_t(y) * size + x] >= 0) continue;
                for (const auto& [dx, dy] : {std::pair{-1, 0}, std::pair{1, 0}, std::pair{0, -1}, std::pair{0, 1}}) {
                    const int nx = x + dx, ny = y + dy;
                    if (nx < 0 || ny < 0 || nx >= size || ny >= size) continue;
                    const float v = value[size_t(ny) * size + nx];
                    if (v >= 0) {
                        next[size_t(y) * size + x] = v;
                        break;
                    }
                }
            }
        value = std::move(next);
    }
    Image img;
    img.width = img.height = size;
    img.rgba.assign(size_t(size) * size * 4, 0);
    for (size_t i = 0; i < value.size(); ++i) {
        const uint8_t code = uint8_t(std::lround(std::clamp(std::max(value[i], 0.0f) / range, 0.0f, 1.0f) * 255.0f));
        img.rgba[4 * i] = img.rgba[4 * i + 1] = img.rgba[4 * i + 2] = code;
        img.rgba[4 * i + 3] = 255;
    }
    return img;
}

} // namespace viscera::render
