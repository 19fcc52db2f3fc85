#include "render/sample_map.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>

namespace viscera::render {
namespace {

Eigen::Vector3d restOf(const RenderMesh& m, uint32_t v) {
    return {m.rest[3 * v], m.rest[3 * v + 1], m.rest[3 * v + 2]};
}

Eigen::Vector3d faceNormal(const RenderMesh& m, size_t f) {
    const Eigen::Vector3d a = restOf(m, m.indices[3 * f]), b = restOf(m, m.indices[3 * f + 1]),
                          c = restOf(m, m.indices[3 * f + 2]);
    return (b - a).cross(c - a);
}

} // namespace

size_t fillSampleClass(RenderMesh& mesh, size_t seedFace, int samples, float maxAngleDeg,
                       const std::vector<int32_t>& faceIsland) {
    const std::string origin = "render::fillSampleClass(): mesh " + mesh.name + ": ";
    if (samples != 0 && samples != 1 && samples != 4 && samples != 8)
        throw std::invalid_argument(origin + "samples must be 0, 1, 4 or 8, got " + std::to_string(samples));
    const size_t faces = mesh.triangleCount();
    if (seedFace >= faces)
        throw std::invalid_argument(origin + "face " + std::to_string(seedFace) + " is out of range (" +
                                    std::to_string(faces) + " faces)");
    if (!(maxAngleDeg >= 0 && maxAngleDeg <= 180))
        throw std::invalid_argument(origin + "the angle must be in [0, 180] degrees, got " +
                                    std::to_string(maxAngleDeg));
    if (!faceIsland.empty() && faceIsland.size() != faces)
        throw std::invalid_argument(origin + std::to_string(faceIsland.size()) + " island ids for " +
                                    std::to_string(faces) + " faces");
    // faces around each undirected edge
    std::map<std::pair<uint32_t, uint32_t>, std::vector<size_t>> edgeFaces;
    for (size_t f = 0; f < faces; ++f)
        for (int k = 0; k < 3; ++k) {
            uint32_t a = mesh.indices[3 * f + k], b = mesh.indices[3 * f + (k + 1) % 3];
            if (a > b) std::swap(a, b);
            edgeFaces[{a, b}].push_back(f);
        }
    const double cosMax = std::cos(maxAngleDeg * 3.14159265358979323846 / 180.0);
    std::vector<uint8_t> reached(faces, 0);
    std::vector<size_t> stack{seedFace};
    reached[seedFace] = 1;
    size_t count = 0;
    while (!stack.empty()) {
        const size_t f = stack.back();
        stack.pop_back();
        ++count;
        const Eigen::Vector3d nf = faceNormal(mesh, f);
        for (int k = 0; k < 3; ++k) {
            uint32_t a = mesh.indices[3 * f + k], b = mesh.indices[3 * f + (k + 1) % 3];
            if (a > b) std::swap(a, b);
            for (size_t g : edgeFaces[{a, b}]) {
                if (reached[g]) continue;
                if (!faceIsland.empty() && faceIsland[g] != faceIsland[f]) continue; // UV border
                const Eigen::Vector3d ng = faceNormal(mesh, g);
                const double denom = nf.norm() * ng.norm();
                if (!(denom > 0) || nf.dot(ng) / denom < cosMax - 1e-12) continue; // sharp edge
                reached[g] = 1;
                stack.push_back(g);
            }
        }
    }
    if (mesh.sampleMap.size() != mesh.vertexCount()) mesh.sampleMap.assign(mesh.vertexCount(), 0.0f);
    for (size_t f = 0; f < faces; ++f)
        if (reached[f])
            for (int k = 0; k < 3; ++k)
                mesh.sampleMap[mesh.indices[3 * f + k]] = static_cast<float>(samples);
    ++mesh.staticRevision;
    return count;
}

std::array<double, 4> sampleClassAreas(const RenderMesh& mesh) {
    std::array<double, 4> area{0, 0, 0, 0};
    auto slot = [](float s) { return s >= 7.5f ? 3 : s >= 3.5f ? 2 : s >= 0.5f ? 1 : 0; };
    for (size_t f = 0; f < mesh.triangleCount(); ++f) {
        const double a = 0.5 * faceNormal(mesh, f).norm() / 3.0;
        for (int k = 0; k < 3; ++k) {
            const uint32_t v = mesh.indices[3 * f + k];
            area[slot(v < mesh.sampleMap.size() ? mesh.sampleMap[v] : 0.0f)] += a;
        }
    }
    return area;
}

} // namespace viscera::render
