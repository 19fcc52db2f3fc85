#include "app/port_overlays.hpp"

#include "app/paint_overlays.hpp"

#include <cmath>

namespace viscera::studio {

std::pair<sim::Vec3, sim::Vec3> basisAbout(const sim::Vec3& a) {
    const sim::Vec3 helper = std::abs(a.z()) < 0.9 ? sim::Vec3::UnitZ() : sim::Vec3::UnitX();
    const sim::Vec3 u = a.cross(helper).normalized();
    return {u, a.cross(u)};
}

void addRing(std::vector<sim::Vec3>& nodes, std::vector<std::array<int32_t, 2>>& edges, const sim::Vec3& c,
             const sim::Vec3& u, const sim::Vec3& v, double r, int n) {
    const auto first = static_cast<int32_t>(nodes.size());
    for (int k = 0; k < n; ++k) {
        const double t = 2 * M_PI * k / n;
        nodes.push_back(c + r * (std::cos(t) * u + std::sin(t) * v));
        edges.push_back({first + k, first + (k + 1) % n});
    }
}

render::RenderMesh portWorkspaceMesh(const sim::PortFrame& port, uint32_t material) {
    const sim::PortDesc& p = port.desc;
    const sim::Vec3& a = port.axis;
    std::vector<sim::Vec3> nodes;
    std::vector<std::array<int32_t, 2>> edges;
    if (!p.position.allFinite() || !a.allFinite() || !(p.insertionMax > 0))
        return lineTubes({}, {}, 1e-3, "port workspace", {0.55f, 0.9f, 1.0f, 1.0f}, material);
    const auto [u, v] = basisAbout(a);
    const double angle = std::clamp(p.maxAngleDeg, 0.0, 89.0) * M_PI / 180.0;
    const double cs = std::cos(angle), sn = std::sin(angle);
    constexpr int kRing = 48, kLines = 16;
    for (double d : {p.insertionMin, p.insertionMax})
        addRing(nodes, edges, p.position + a * (d * cs), u, v, d * sn, kRing);
    const auto apex = static_cast<int32_t>(nodes.size());
    nodes.push_back(p.position);
    const int32_t outerRing = kRing; // the second ring's first node
    for (int k = 0; k < kLines; ++k)
        edges.push_back({apex, outerRing + k * (kRing / kLines)});
    nodes.push_back(p.position - a * (0.25 * p.insertionMax)); // the shaft's side, outside
    edges.push_back({apex, apex + 1});
    return lineTubes(std::move(nodes), std::move(edges), 0.004 * p.insertionMax, "port workspace",
                     {0.55f, 0.9f, 1.0f, 1.0f}, material);
}

render::RenderMesh reachMarkersMesh(const std::vector<ReachMarker>& markers, double size, uint32_t material) {
    std::vector<sim::Vec3> nodes;
    std::vector<std::array<int32_t, 2>> edges;
    std::vector<bool> reachedEdge;
    size = std::max(size, 1e-4);
    for (const ReachMarker& m : markers) {
        if (!m.point.allFinite()) continue;
        for (int axis = 0; axis < 3; ++axis) {
            const auto first = static_cast<int32_t>(nodes.size());
            nodes.push_back(m.point - size * sim::Vec3::Unit(axis));
            nodes.push_back(m.point + size * sim::Vec3::Unit(axis));
            edges.push_back({first, first + 1});
            reachedEdge.push_back(m.reached);
        }
    }
    render::RenderMesh mesh = lineTubes(nodes, edges, 0.15 * size, "port targets", {0.2f, 0.85f, 0.3f, 1.0f}, material);
    // lineTubes makes each edge's tube of kTubeVertices vertices in edge order (no edge here is
    // degenerate): the unreached crosses' tubes are recoloured red
    constexpr size_t kTubeVertices = 12;
    if (mesh.overlay.size() != 4 * kTubeVertices * edges.size()) return mesh;
    for (size_t e = 0; e < edges.size(); ++e) {
        if (reachedEdge[e]) continue;
        for (size_t k = e * kTubeVertices; k < (e + 1) * kTubeVertices; ++k) {
            mesh.overlay[4 * k] = 0.95f;
            mesh.overlay[4 * k + 1] = 0.15f;
            mesh.overlay[4 * k + 2] = 0.1f;
        }
    }
    return mesh;
}

std::vector<render::RenderMesh> portGizmoMeshes(const sim::Vec3& at, double length, uint32_t material) {
    std::vector<render::RenderMesh> meshes;
    if (!at.allFinite() || !(length > 0)) return meshes;
    const Eigen::Vector4f colours[3] = {
        {0.95f, 0.25f, 0.2f, 1.0f}, {0.3f, 0.85f, 0.3f, 1.0f}, {0.3f, 0.5f, 1.0f, 1.0f}};
    const char* names[3] = {"port gizmo x", "port gizmo y", "port gizmo z"};
    for (int k = 0; k < 3; ++k) {
        // a rod with a cross-bar at its end (where the grip is easiest to see)
        const sim::Vec3 e = sim::Vec3::Unit(k), side = sim::Vec3::Unit((k + 1) % 3) * (0.2 * length);
        const sim::Vec3 end = at + length * e;
        meshes.push_back(lineTubes({at, end, end - side, end + side}, {{0, 1}, {2, 3}}, 0.06 * length, names[k],
                                   colours[k], material));
    }
    return meshes;
}

} // namespace viscera::studio
