#include "render/backend.hpp"

#include <Eigen/Geometry>

namespace viscera::render {

void MockBackend::resize(const FrameLayout& layout) {
    if (layout == m_layout) return;
    m_layout = layout;
    ++m_stats.targetAllocations;
}

void MockBackend::createMesh(size_t index, const RenderMesh& mesh) {
    if (m_meshes.size() <= index) m_meshes.resize(index + 1);
    m_meshes[index] = {mesh.vertexCount(), mesh.triangleCount(), 0, mesh.triangleCount(), 0, mesh.indices};
    m_stats.bufferAllocations += 4; // positions (current, previous), normals, static attributes
}

void MockBackend::updateMesh(size_t index, const RenderMesh& mesh, bool staticChanged) {
    MeshRecord& r = m_meshes.at(index);
    if (r.vertices != mesh.vertexCount()) return; // the Renderer never lets this happen
    ++r.updates;
    m_stats.bufferUpdates += staticChanged ? 4 : 3;
}

void MockBackend::updateFaceMask(size_t index, const RenderMesh& mesh) {
    MeshRecord& r = m_meshes.at(index);
    if (r.triangles != mesh.triangleCount()) return; // the Renderer never lets this happen
    mesh.drawnIndicesInto(r.drawnIndices);
    r.drawnTriangles = r.drawnIndices.size() / 3;
    ++r.maskUpdates;
    ++m_stats.bufferUpdates;
}

void MockBackend::runPass(const PassDesc& pass, const PassContext& ctx) {
    m_passes.push_back(pass);
    ++m_stats.passesRun;
    if (pass.kind == PassKind::GBuffer)
        for (const RenderMesh& m : ctx.view.meshes()) {
            if (!m.visible) continue;
            ++m_stats.drawCalls;
            const MaterialMaps* maps =
                m.material < ctx.view.materials().size() ? ctx.view.materials()[m.material].maps.get() : nullptr;
            const bool mapped = maps && (!maps->diffuse.empty() || !maps->roughness.empty() ||
                                         !maps->metallic.empty() || !maps->normal.empty());
            m_stats.mappedDraws += mapped ? 1 : 0;
        }
    if (pass.kind == PassKind::Lighting) {
        m_samples.assign(ctx.view.meshes().size(), {});
        for (size_t i = 0; i < ctx.view.meshes().size(); ++i) {
            const RenderMesh& m = ctx.view.meshes()[i];
            for (size_t v = 0; v < m.vertexCount(); ++v) {
                const float d = (Eigen::Map<const Eigen::Vector3f>(&m.positions[3 * v]) - ctx.light.center).norm();
                const float painted = v < m.sampleMap.size() ? m.sampleMap[v] : 0.0f; // the map may be absent
                m_samples[i].push_back(samplesFor(ctx.settings.sampling, d, int(painted + 0.5f)));
            }
        }
    }
}

Image MockBackend::readPixels(ImageStage) {
    Image img;
    img.width = m_layout.outputWidth;
    img.height = m_layout.outputHeight;
    img.rgba.assign(size_t(img.width) * img.height * 4, 0);
    return img;
}

std::vector<float> MockBackend::readDepth() {
    return std::vector<float>(size_t(m_layout.eyeWidth) * m_layout.eyeHeight, 1.0f);
}

} // namespace viscera::render
