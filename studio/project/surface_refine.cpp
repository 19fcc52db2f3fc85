#include "project/surface_refine.hpp"

#include <cstdint>
#include <map>
#include <utility>
#include <vector>

namespace viscera::studio {

namespace {

sim::TriMesh subdivideOnce(const sim::TriMesh& mesh) {
    std::vector<sim::Vec3> pos = mesh.positions();
    std::map<std::pair<int32_t, int32_t>, int32_t> midpoint; // shared by the edge's two triangles
    auto mid = [&](int32_t a, int32_t b) {
        const std::pair<int32_t, int32_t> key = a < b ? std::pair(a, b) : std::pair(b, a);
        auto [it, fresh] = midpoint.try_emplace(key, static_cast<int32_t>(pos.size()));
        if (fresh) pos.push_back(0.5 * (pos[a] + pos[b]));
        return it->second;
    };
    std::vector<sim::Tri> tris;
    tris.reserve(mesh.triangles().size() * 4);
    for (const sim::Tri& t : mesh.triangles()) {
        const int32_t ab = mid(t[0], t[1]), bc = mid(t[1], t[2]), ca = mid(t[2], t[0]);
        tris.push_back({t[0], ab, ca});
        tris.push_back({ab, t[1], bc});
        tris.push_back({ca, bc, t[2]});
        tris.push_back({ab, bc, ca});
    }
    return sim::TriMesh::fromArrays(std::move(pos), std::move(tris), "subdivided layer");
}

} // namespace

sim::TriMesh midpointSubdivide(const sim::TriMesh& mesh, int times) {
    sim::TriMesh out = mesh;
    for (int k = 0; k < times; ++k)
        out = subdivideOnce(out);
    return out;
}

} // namespace viscera::studio
