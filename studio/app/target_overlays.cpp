#include "app/target_overlays.hpp"

#include "app/paint_overlays.hpp"
#include "app/port_overlays.hpp"

#include <cmath>

namespace viscera::studio {

namespace {

using Edges = std::vector<std::array<int32_t, 2>>;

/// A cross of half size `h` about `c` along the axes.
void addCross(std::vector<sim::Vec3>& nodes, Edges& edges, const sim::Vec3& c, double h) {
    for (int axis = 0; axis < 3; ++axis) {
        const auto first = static_cast<int32_t>(nodes.size());
        nodes.push_back(c - h * sim::Vec3::Unit(axis));
        nodes.push_back(c + h * sim::Vec3::Unit(axis));
        edges.push_back({first, first + 1});
    }
}

/// A polyline through `points`.
void addPolyline(std::vector<sim::Vec3>& nodes, Edges& edges, const std::vector<sim::Vec3>& points) {
    const auto first = static_cast<int32_t>(nodes.size());
    for (size_t i = 0; i < points.size(); ++i) {
        nodes.push_back(points[i]);
        if (i > 0) edges.push_back({first + static_cast<int32_t>(i) - 1, first + static_cast<int32_t>(i)});
    }
}

bool finite(const std::vector<sim::Vec3>& points) {
    for (const sim::Vec3& p : points)
        if (!p.allFinite()) return false;
    return true;
}

} // namespace

render::RenderMesh cutTargetsMesh(const std::vector<sim::CutTarget>& cuts, uint32_t material) {
    std::vector<sim::Vec3> nodes;
    Edges edges;
    constexpr double kRingEvery = 0.01; // m
    for (const sim::CutTarget& c : cuts) {
        if (c.line.size() < 2 || !finite(c.line) || !(c.radius > 0)) continue;
        addPolyline(nodes, edges, c.line);
        double since = kRingEvery;
        for (size_t i = 0; i < c.line.size(); ++i) {
            const size_t a = i == 0 ? 0 : i - 1, b = i == 0 ? 1 : i;
            const sim::Vec3 d = c.line[b] - c.line[a];
            if (i > 0) since += d.norm();
            if (!(d.norm() > 0) || (since < kRingEvery && i + 1 < c.line.size())) continue;
            const auto [u, v] = basisAbout(d.normalized());
            addRing(nodes, edges, c.line[i], u, v, c.radius, 24);
            since = 0;
        }
    }
    render::RenderMesh mesh =
        lineTubes(std::move(nodes), std::move(edges), 7e-4, "cut targets", {1.0f, 0.55f, 0.1f, 1.0f}, material);
    mesh.drawOnTop = true; // the line lies on the surface
    return mesh;
}

render::RenderMesh clipTargetsMesh(const std::vector<sim::ClipTarget>& clips, uint32_t material) {
    std::vector<sim::Vec3> nodes;
    Edges edges;
    for (const sim::ClipTarget& c : clips) {
        if (!c.position.allFinite() || !(c.tolerance > 0)) continue;
        addCross(nodes, edges, c.position, 0.002);
        for (int axis = 0; axis < 3; ++axis)
            addRing(nodes, edges, c.position, sim::Vec3::Unit((axis + 1) % 3), sim::Vec3::Unit((axis + 2) % 3),
                    c.tolerance, 24);
    }
    return lineTubes(std::move(nodes), std::move(edges), 4e-4, "clip targets", {1.0f, 0.9f, 0.15f, 1.0f}, material);
}

render::RenderMesh sutureTargetMesh(const sim::SutureTarget& s, double size, uint32_t material) {
    std::vector<sim::Vec3> nodes;
    Edges edges;
    if (s.planePoint.allFinite() && s.planeNormal.allFinite() && s.planeNormal.norm() > 0 && size > 0) {
        const sim::Vec3 n = s.planeNormal.normalized();
        const auto [u, v] = basisAbout(n);
        const double h = 0.5 * size;
        const std::vector<sim::Vec3> square{s.planePoint + h * (u + v), s.planePoint + h * (-u + v),
                                            s.planePoint + h * (-u - v), s.planePoint + h * (u - v),
                                            s.planePoint + h * (u + v)};
        addPolyline(nodes, edges, square);
        addPolyline(nodes, edges, {s.planePoint - h * n, s.planePoint + h * n});
        for (double side : {-1.0, 1.0})
            addRing(nodes, edges, s.planePoint + side * h * n, u, v, s.spacingMax, 24);
    }
    return lineTubes(std::move(nodes), std::move(edges), 4e-4, "suture target", {0.9f, 0.3f, 0.9f, 1.0f}, material);
}

render::RenderMesh pendingTargetMesh(const std::vector<sim::Vec3>& stroke, const std::optional<sim::Vec3>& point,
                                     uint32_t material) {
    std::vector<sim::Vec3> nodes;
    Edges edges;
    if (stroke.size() >= 2 && finite(stroke)) addPolyline(nodes, edges, stroke);
    if (point && point->allFinite()) addCross(nodes, edges, *point, 0.003);
    render::RenderMesh mesh =
        lineTubes(std::move(nodes), std::move(edges), 6e-4, "target stroke", {1.0f, 1.0f, 1.0f, 1.0f}, material);
    mesh.drawOnTop = true;
    return mesh;
}

} // namespace viscera::studio
