#include "app/paint_overlays.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace viscera::studio {
namespace {

/// Fills the per-vertex arrays of a static authoring mesh from its positions and indices.
void finish(render::RenderMesh& m) {
    const size_t v = m.positions.size() / 3;
    m.rest = m.positions;
    m.thickness.assign(v, 0.01f);
    m.sampleMap.assign(v, 0.0f);
    m.heat.assign(v, 0.0f);
    m.normals.assign(3 * v, 0.0f);
    for (size_t f = 0; f + 2 < m.indices.size(); f += 3) {
        auto p = [&](uint32_t i) {
            return Eigen::Vector3f(m.positions[3 * i], m.positions[3 * i + 1], m.positions[3 * i + 2]);
        };
        const Eigen::Vector3f n = (p(m.indices[f + 1]) - p(m.indices[f])).cross(p(m.indices[f + 2]) - p(m.indices[f]));
        for (int k = 0; k < 3; ++k)
            for (int c = 0; c < 3; ++c)
                m.normals[3 * m.indices[f + k] + c] += n[c];
    }
    for (size_t i = 0; i < v; ++i) {
        Eigen::Map<Eigen::Vector3f> n(&m.normals[3 * i]);
        const float len = n.norm();
        n = len > 0 ? Eigen::Vector3f(n / len) : Eigen::Vector3f::UnitZ();
    }
    m.source = render::RenderMesh::Source::Static;
}

void push(std::vector<float>& xyz, const Eigen::Vector3d& p) {
    xyz.push_back(static_cast<float>(p.x()));
    xyz.push_back(static_cast<float>(p.y()));
    xyz.push_back(static_cast<float>(p.z()));
}

void pushColour(std::vector<float>& rgba, const Eigen::Vector4f& c) {
    rgba.insert(rgba.end(), {c[0], c[1], c[2], c[3]});
}

} // namespace

Eigen::Vector4f weightColour(double w, double base) {
    const double r = std::isfinite(w) && w > 0 && base > 0 ? std::log(w / base) / std::log(4.0) : 0.0;
    const float t = static_cast<float>(std::clamp(r, -1.0, 1.0));
    const Eigen::Vector3f grey(0.55f, 0.55f, 0.55f), hot(0.9f, 0.1f, 0.05f), cold(0.1f, 0.3f, 0.95f);
    const Eigen::Vector3f c =
        t >= 0 ? Eigen::Vector3f(grey + t * (hot - grey)) : Eigen::Vector3f(grey - t * (cold - grey));
    return {c.x(), c.y(), c.z(), w == base ? 0.35f : 0.9f};
}

render::RenderMesh brushRingMesh(const Eigen::Vector3d& centre, const Eigen::Vector3d& normal, double radius,
                                 uint32_t material) {
    render::RenderMesh m;
    m.name = "brush";
    m.material = material;
    m.doubleSided = true;
    if (!(radius > 0) || !centre.allFinite() || !(normal.norm() > 0) || !normal.allFinite()) return m;
    const Eigen::Vector3d n = normal.normalized(), u = n.unitOrthogonal(), w = n.cross(u);
    const double band = std::max(0.04 * radius, 1.5e-4);
    const Eigen::Vector3d c = centre + 0.01 * radius * n;
    constexpr int kSegments = 48;
    for (int k = 0; k < kSegments; ++k) {
        const double phi = 2 * 3.14159265358979 * k / kSegments;
        const Eigen::Vector3d dir = std::cos(phi) * u + std::sin(phi) * w;
        push(m.positions, c + (radius - 0.5 * band) * dir);
        push(m.positions, c + (radius + 0.5 * band) * dir);
    }
    for (uint32_t k = 0; k < kSegments; ++k) {
        const uint32_t i0 = 2 * k, o0 = i0 + 1, i1 = 2 * ((k + 1) % kSegments), o1 = i1 + 1;
        m.indices.insert(m.indices.end(), {i0, i1, o1, i0, o1, o0});
    }
    finish(m);
    m.overlay.clear();
    for (size_t i = 0; i < m.positions.size() / 3; ++i)
        pushColour(m.overlay, {1.0f, 0.95f, 0.55f, 1.0f});
    return m;
}

render::RenderMesh lineTubes(std::vector<sim::Vec3> nodes, std::vector<std::array<int32_t, 2>> edges, double radius,
                             const char* name, const Eigen::Vector4f& rgba, uint32_t material) {
    sim::Skeleton lines;
    lines.nodes = std::move(nodes);
    for (const auto& e : edges)
        lines.edges.push_back({e[0], e[1]});
    render::RenderMesh m = skeletonMesh(lines, static_cast<float>(radius), material);
    m.name = name;
    m.overlay.clear();
    for (size_t i = 0; i < m.vertexCount(); ++i)
        pushColour(m.overlay, rgba);
    return m;
}

render::RenderMesh gridMesh(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, uint32_t material) {
    const double size = std::max({hi.x() - lo.x(), hi.y() - lo.y(), 1e-3});
    const double raw = size / 5, mag = std::pow(10.0, std::floor(std::log10(raw))), f = raw / mag;
    const double step = mag * (f < 1.5 ? 1.0 : f < 3.5 ? 2.0 : f < 7.5 ? 5.0 : 10.0);
    const Eigen::Vector2d c(0.5 * (lo.x() + hi.x()), 0.5 * (lo.y() + hi.y()));
    const double half = 0.75 * size;
    const double x0 = std::floor((c.x() - half) / step) * step, y0 = std::floor((c.y() - half) / step) * step;
    const double x1 = std::ceil((c.x() + half) / step) * step, y1 = std::ceil((c.y() + half) / step) * step;
    std::vector<sim::Vec3> nodes;
    std::vector<std::array<int32_t, 2>> edges;
    auto line = [&](const sim::Vec3& a, const sim::Vec3& b) {
        edges.push_back({static_cast<int32_t>(nodes.size()), static_cast<int32_t>(nodes.size() + 1)});
        nodes.push_back(a);
        nodes.push_back(b);
    };
    for (double x = x0; x <= x1 + 0.5 * step; x += step)
        line({x, y0, lo.z()}, {x, y1, lo.z()});
    for (double y = y0; y <= y1 + 0.5 * step; y += step)
        line({x0, y, lo.z()}, {x1, y, lo.z()});
    return lineTubes(std::move(nodes), std::move(edges), 0.002 * size, "grid", {0.42f, 0.43f, 0.46f, 1.0f}, material);
}

render::RenderMesh boxOutlineMesh(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, uint32_t material,
                                  const char* name, const Eigen::Vector4f& rgba) {
    std::vector<sim::Vec3> nodes;
    for (int k = 0; k < 8; ++k)
        nodes.emplace_back(k & 1 ? hi.x() : lo.x(), k & 2 ? hi.y() : lo.y(), k & 4 ? hi.z() : lo.z());
    std::vector<std::array<int32_t, 2>> edges;
    for (int32_t a = 0; a < 8; ++a)
        for (int bit : {1, 2, 4})
            if (!(a & bit)) edges.push_back({a, a | bit});
    return lineTubes(std::move(nodes), std::move(edges), 0.004 * (hi - lo).norm(), name, rgba, material);
}

render::RenderMesh skeletonMesh(const sim::Skeleton& skeleton, float radius, uint32_t material) {
    render::RenderMesh m;
    m.name = "skeleton";
    m.material = material;
    m.doubleSided = true;
    constexpr int kSides = 6;
    for (const auto& e : skeleton.edges) {
        const Eigen::Vector3d a = skeleton.nodes[e[0]], b = skeleton.nodes[e[1]];
        const Eigen::Vector3d axis = b - a;
        if (!(axis.norm() > 0)) continue;
        const Eigen::Vector3d d = axis.normalized();
        const Eigen::Vector3d u = d.unitOrthogonal(), w = d.cross(u);
        const uint32_t first = static_cast<uint32_t>(m.positions.size() / 3);
        for (int k = 0; k < kSides; ++k) {
            const double phi = 2 * 3.14159265358979 * k / kSides;
            const Eigen::Vector3d off = radius * (std::cos(phi) * u + std::sin(phi) * w);
            push(m.positions, a + off);
            push(m.positions, b + off);
        }
        for (int k = 0; k < kSides; ++k) {
            const uint32_t a0 = first + 2 * k, b0 = a0 + 1, a1 = first + 2 * ((k + 1) % kSides), b1 = a1 + 1;
            m.indices.insert(m.indices.end(), {a0, a1, b1, a0, b1, b0});
        }
    }
    finish(m);
    m.overlay.clear();
    for (size_t i = 0; i < m.positions.size() / 3; ++i)
        pushColour(m.overlay, {1.0f, 0.85f, 0.1f, 1.0f});
    return m;
}

render::RenderMesh sliceMesh(const sim::TetMesh& mesh, const std::vector<double>& weights, double base,
                             const CutPlane& plane, uint32_t material) {
    render::RenderMesh m;
    m.name = "slice";
    m.material = material;
    m.doubleSided = true;
    const auto& x = mesh.positions();
    static constexpr std::array<std::array<int, 2>, 6> kEdges = {{{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}}};
    for (const sim::Tet& t : mesh.tets()) {
        std::array<double, 4> s;
        for (int k = 0; k < 4; ++k)
            s[k] = plane.normal.dot(x[t[k]]) - plane.offset;
        std::vector<Eigen::Vector3d> pts;
        std::vector<double> wts;
        for (const auto& e : kEdges) {
            const double sa = s[e[0]], sb = s[e[1]];
            if ((sa > 0) == (sb > 0)) continue;
            const double f = sa / (sa - sb);
            pts.push_back(x[t[e[0]]] + f * (x[t[e[1]]] - x[t[e[0]]]));
            const double wa = weights.empty() ? base : weights[t[e[0]]], wb = weights.empty() ? base : weights[t[e[1]]];
            wts.push_back(wa + f * (wb - wa));
        }
        if (pts.size() < 3) continue;
        // order the 3 or 4 points around their centre in the plane
        Eigen::Vector3d c = Eigen::Vector3d::Zero();
        for (const auto& p : pts)
            c += p;
        c /= static_cast<double>(pts.size());
        const Eigen::Vector3d u = plane.normal.unitOrthogonal(), v = plane.normal.cross(u);
        std::vector<size_t> order(pts.size());
        for (size_t k = 0; k < order.size(); ++k)
            order[k] = k;
        std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
            return std::atan2((pts[a] - c).dot(v), (pts[a] - c).dot(u)) <
                   std::atan2((pts[b] - c).dot(v), (pts[b] - c).dot(u));
        });
        const uint32_t first = static_cast<uint32_t>(m.positions.size() / 3);
        for (size_t k : order) {
            push(m.positions, pts[k]);
            pushColour(m.overlay, weightColour(wts[k], base));
        }
        for (uint32_t k = 1; k + 1 < pts.size(); ++k)
            m.indices.insert(m.indices.end(), {first, first + k + 1, first + k}); // faces −n
    }
    std::vector<float> overlay = std::move(m.overlay);
    finish(m);
    m.overlay = std::move(overlay);
    for (size_t i = 3; i < m.overlay.size(); i += 4) // a section shows the ramp fully
        m.overlay[i] = 1.0f;
    return m;
}

std::vector<uint8_t> cutAwayMask(const render::RenderMesh& body, const CutPlane& plane) {
    std::vector<uint8_t> mask(body.triangleCount(), 1);
    for (size_t f = 0; f < body.triangleCount(); ++f) {
        Eigen::Vector3d c = Eigen::Vector3d::Zero();
        for (int k = 0; k < 3; ++k) {
            const uint32_t v = body.indices[3 * f + k];
            c += Eigen::Vector3d(body.rest[3 * v], body.rest[3 * v + 1], body.rest[3 * v + 2]);
        }
        mask[f] = plane.normal.dot(c / 3.0) - plane.offset > 0 ? 0 : 1;
    }
    return mask;
}

} // namespace viscera::studio
