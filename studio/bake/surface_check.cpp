#include "bake/surface_check.hpp"

#include "sim/util/error.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

namespace viscera::bake::detail {
namespace {

[[noreturn]] void fail(const std::string& label, const std::string& message) {
    throw InputError(label + ": " + message);
}

std::string edgeName(int32_t a, int32_t b) {
    return "edge (" + std::to_string(a) + ", " + std::to_string(b) + ")";
}

uint64_t edgeKey(int32_t a, int32_t b) {
    return (static_cast<uint64_t>(static_cast<uint32_t>(a)) << 32) | static_cast<uint32_t>(b);
}

} // namespace

void checkInputSurface(const std::string& label, const sim::TriMesh& surface) {
    if (surface.triangleCount() == 0) fail(label, "surface has no triangles");
    for (size_t v = 0; v < surface.vertexCount(); ++v)
        if (!surface.positions()[v].allFinite())
            fail(label, "vertex " + std::to_string(v) + " has a non-finite coordinate");
    for (size_t t = 0; t < surface.triangleCount(); ++t)
        for (int32_t v : surface.triangles()[t])
            if (v < 0 || static_cast<size_t>(v) >= surface.vertexCount())
                fail(label, "triangle " + std::to_string(t) + " references vertex " + std::to_string(v) +
                                " (the surface has " + std::to_string(surface.vertexCount()) + " vertices)");
    // Topology: every edge shared by exactly two triangles that traverse it in opposite
    // directions, and every vertex a single fan of triangles.
    const auto& tris = surface.triangles();
    const int32_t nt = static_cast<int32_t>(tris.size());

    std::unordered_map<uint64_t, std::array<int32_t, 3>> undirected; // count, first two tris
    undirected.reserve(tris.size() * 2);
    for (int32_t t = 0; t < nt; ++t)
        for (int k = 0; k < 3; ++k) {
            const int32_t a = tris[t][k], b = tris[t][(k + 1) % 3];
            auto& u = undirected[edgeKey(std::min(a, b), std::max(a, b))];
            if (u[0] < 2) u[1 + u[0]] = t;
            ++u[0];
        }
    for (int32_t t = 0; t < nt; ++t)
        for (int k = 0; k < 3; ++k) {
            const int32_t a = std::min(tris[t][k], tris[t][(k + 1) % 3]);
            const int32_t b = std::max(tris[t][k], tris[t][(k + 1) % 3]);
            const auto& u = undirected.at(edgeKey(a, b));
            if (u[0] > 2)
                fail(label, "surface is not manifold: " + edgeName(a, b) + " is shared by " + std::to_string(u[0]) +
                                " triangles (a closed surface has 2)");
        }

    std::unordered_map<uint64_t, int32_t> directed; // directed edge -> its triangle
    directed.reserve(tris.size() * 3);
    for (int32_t t = 0; t < nt; ++t)
        for (int k = 0; k < 3; ++k) {
            const int32_t a = tris[t][k], b = tris[t][(k + 1) % 3];
            const auto [it, inserted] = directed.try_emplace(edgeKey(a, b), t);
            if (!inserted)
                fail(label, "surface is not consistently oriented: " + edgeName(a, b) +
                                " is traversed in the same direction by triangles " + std::to_string(it->second) +
                                " and " + std::to_string(t));
        }
    for (int32_t t = 0; t < nt; ++t)
        for (int k = 0; k < 3; ++k) {
            const int32_t a = tris[t][k], b = tris[t][(k + 1) % 3];
            if (!directed.contains(edgeKey(b, a)))
                fail(label, "surface is not closed: " + edgeName(a, b) + " belongs to only one triangle (" +
                                std::to_string(t) + ")");
        }

    // Fans: rotate around each vertex through the triangle owning the reversed previous edge.
    std::vector<char> visited(tris.size() * 3, 0);
    std::vector<int32_t> fans(surface.vertexCount(), 0);
    for (int32_t t = 0; t < nt; ++t)
        for (int i = 0; i < 3; ++i) {
            if (visited[3 * t + i]) continue;
            const int32_t v = tris[t][i];
            if (++fans[v] > 1)
                fail(label, "surface is not manifold at vertex " + std::to_string(v) +
                                ": its triangles form more than one fan (surfaces touch there)");
            int32_t ct = t, ci = i;
            while (!visited[3 * ct + ci]) {
                visited[3 * ct + ci] = 1;
                const int32_t prev = tris[ct][(ci + 2) % 3];
                ct = directed.at(edgeKey(v, prev));
                ci = tris[ct][0] == v ? 0 : tris[ct][1] == v ? 1 : 2;
            }
        }
}

} // namespace viscera::bake::detail
