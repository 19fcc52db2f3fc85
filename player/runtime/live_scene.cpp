#include "runtime/live_scene.hpp"

namespace viscera::player {

LiveScene::LiveScene(const LoadedCase& loaded) : m_view(caseView(loaded)) {
    const sim::World& world = *loaded.world;
    for (size_t b = 0; b < world.bodyCount(); ++b) {
        m_bodyOffset.push_back(m_offset);
        m_offset += world.restMesh(b).vertexCount();
    }
}

void LiveScene::addTools(const render::ToolPoses& first) {
    m_tools = render::ToolMeshes(m_view, first);
}

bool LiveScene::apply(const LiveGeometry& g) {
    if (g.nodes.size() != m_offset) return false;
    // The fat's cut first: its cut mesh's slots name the nodes the copy below reads.
    for (size_t b = 0; b < g.bodyTetMasks.size(); ++b)
        if (!g.bodyTetMasks[b].empty()) m_view.setBodyCut(b, g.bodyTetMasks[b]);
    for (size_t i = 0; i < m_view.meshes().size(); ++i) {
        render::RenderMesh& m = m_view.meshes()[i];
        const std::vector<sim::Vec3>* src = nullptr;
        size_t base = 0;
        if (m.source == render::RenderMesh::Source::Body && m.sourceIndex < m_bodyOffset.size()) {
            src = &g.nodes;
            base = m_bodyOffset[m.sourceIndex];
        } else if (m.source == render::RenderMesh::Source::Surface && m.sourceIndex < g.surfaces.size()) {
            src = &g.surfaces[m.sourceIndex];
        }
        if (!src) continue;
        const size_t end = m.source == render::RenderMesh::Source::Body && m.sourceIndex + 1 < m_bodyOffset.size()
                               ? m_bodyOffset[m.sourceIndex + 1]
                               : src->size();
        for (size_t v = 0; v < m.sourceVertex.size(); ++v) {
            if (m.sourceVertex[v] < 0) continue;
            const size_t k = base + static_cast<size_t>(m.sourceVertex[v]);
            if (k >= end || k >= src->size()) continue;
            for (int r = 0; r < 3; ++r)
                m.positions[3 * v + r] = static_cast<float>((*src)[k][r]);
        }
        m_view.recomputeNormals(i);
        // The cut [A §5.3.1]: dropped faces and the heat tint along it.
        const size_t s = m.sourceIndex;
        const std::vector<float>* heat = nullptr;
        if (m.source == render::RenderMesh::Source::Surface) {
            if (s < g.surfaceMasks.size() && g.surfaceMasks[s].size() == m.triangleCount())
                m_view.setFaceMask(i, g.surfaceMasks[s]);
            if (s < g.surfaceHeat.size()) heat = &g.surfaceHeat[s];
        } else if (s < g.bodyHeat.size()) {
            heat = &g.bodyHeat[s];
        }
        if (heat && !heat->empty()) m_view.setSourceHeat(i, *heat);
    }
    m_tools.update(m_view, g.tools);
    return true;
}

} // namespace viscera::player
