#include "render/embedded_tint.hpp"

#include "render/material.hpp"
#include "sim/scene/world.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace viscera::render {

size_t tintSurfacesOverEmbeddedBodies(SceneView& view, const sim::World& world, const EmbeddedTint& tint) {
    std::vector<size_t> embedded;
    for (size_t b = 0; b < world.bodyCount() && b < world.scene().bodies.size(); ++b)
        if (!world.scene().bodies[b].embeddedIn.empty()) embedded.push_back(b);
    if (embedded.empty() || !(tint.depth > 0)) return 0;
    size_t tinted = 0;
    for (size_t i = 0; i < view.meshes().size(); ++i) {
        const RenderMesh& m = view.meshes()[i];
        if (m.source != RenderMesh::Source::Surface || m.sourceIndex >= world.surfaceCount()) continue;
        const auto& rest = world.surfaceMesh(m.sourceIndex).positions();
        std::vector<float> rgba(4 * m.vertexCount(), 0.0f);
        for (size_t v = 0; v < m.vertexCount(); ++v) {
            const int32_t sv = v < m.sourceVertex.size() ? m.sourceVertex[v] : -1;
            if (sv < 0 || static_cast<size_t>(sv) >= rest.size()) continue;
            float best = 0.0f;
            Eigen::Vector3f colour = Eigen::Vector3f::Zero();
            for (size_t b : embedded) {
                double d2 = std::numeric_limits<double>::infinity();
                for (const sim::Vec3& p : world.restMesh(b).positions())
                    d2 = std::min(d2, (p - rest[sv]).squaredNorm());
                const float w = tint.strength * static_cast<float>(std::exp(-std::sqrt(d2) / tint.depth));
                if (w > best) {
                    best = w;
                    colour = 0.75f * defaultMaterialFor(world.bodyName(b)).surface.colour; // seen through a layer
                }
            }
            for (int c = 0; c < 3; ++c)
                rgba[4 * v + c] = colour[c];
            rgba[4 * v + 3] = best;
            if (best > 0.05f) ++tinted;
        }
        view.setOverlay(i, rgba);
    }
    return tinted;
}

} // namespace viscera::render
