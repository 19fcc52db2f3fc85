#include "render/renderer.hpp"

#include <chrono>
#include <stdexcept>

namespace viscera::render {

namespace {
using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}
} // namespace

double FrameStats::passMs(const std::string& name) const {
    double sum = 0;
    for (const PassTiming& p : passes)
        if (p.name == name) sum += p.ms;
    return sum;
}

Renderer::Renderer(std::unique_ptr<Backend> backend, const RenderSettings& settings) : m_backend(std::move(backend)) {
    if (!m_backend) throw std::invalid_argument("render::Renderer: backend is null");
    setSettings(settings);
}

void Renderer::setSettings(const RenderSettings& settings) {
    settings.validate();
    m_settings = settings;
}

void Renderer::syncMeshes(const SceneView& view) {
    const auto& meshes = view.meshes();
    if (m_meshes.size() < meshes.size()) m_meshes.resize(meshes.size());
    for (size_t i = 0; i < meshes.size(); ++i) {
        const RenderMesh& m = meshes[i];
        MeshState& s = m_meshes[i];
        if (s.broken) continue;
        if (s.revision == ~uint64_t(0)) {
            m_backend->createMesh(i, m);
            s.vertices = m.vertexCount();
            s.indices = m.indices.size();
            m_backend->updateMesh(i, m, true);
            if (!m.faceMask.empty()) m_backend->updateFaceMask(i, m);
            s.revision = m.revision;
            s.staticRevision = m.staticRevision;
            s.faceMaskRevision = m.faceMaskRevision;
            continue;
        }
        if (m.vertexCount() != s.vertices || m.indices.size() != s.indices) {
            s.broken = true;
            m_warnings.push_back("render::Renderer: mesh " + m.name +
                                 " changed its vertex or index count after "
                                 "upload; it is no longer drawn");
            continue;
        }
        const bool staticChanged = m.staticRevision != s.staticRevision;
        if (m.revision != s.revision || staticChanged) {
            m_backend->updateMesh(i, m, staticChanged);
            s.revision = m.revision;
            s.staticRevision = m.staticRevision;
        }
        if (m.faceMaskRevision != s.faceMaskRevision) {
            m_backend->updateFaceMask(i, m);
            s.faceMaskRevision = m.faceMaskRevision;
        }
    }
}

const FrameStats& Renderer::renderFrame(const SceneView& view) {
    const auto frameStart = Clock::now();
    m_stats = {};
    m_stats.frameIndex = m_frame;
    const FrameLayout layout = frameLayout(m_settings);
    m_backend->resize(layout);

    auto t0 = Clock::now();
    syncMeshes(view);
    if (m_settings.timePasses) m_backend->finish();
    m_stats.uploadMs = msSince(t0);

    const float aspect = float(layout.eyeWidth) / float(layout.eyeHeight);
    m_previousEyes = m_eyes;
    const EyeView mono = monoEye(m_settings.camera, aspect);
    if (layout.eyes == 2)
        m_eyes = stereoEyes(m_settings.camera, m_settings.stereo, aspect);
    else
        m_eyes = {mono, mono};
    if (m_frame == 0) m_previousEyes = m_eyes;
    m_light = lightFrame(m_settings.light, mono);

    for (const PassDesc& pass : planFrame(m_settings)) {
        t0 = Clock::now();
        const PassContext ctx{m_settings, view, m_eyes[pass.eye], m_previousEyes[pass.eye], m_light, m_frame};
        m_backend->runPass(pass, ctx);
        if (m_settings.timePasses) m_backend->finish();
        m_stats.passes.push_back({passName(pass.kind), pass.eye, msSince(t0)});
    }
    if (!m_settings.timePasses) m_backend->finish();
    m_stats.totalMs = msSince(frameStart);
    ++m_frame;
    return m_stats;
}

std::vector<float> Renderer::distanceMap(const Eigen::Vector3f& point) {
    const FrameLayout layout = frameLayout(m_settings);
    const std::vector<float> depth = m_backend->readDepth();
    const EyeView& e = m_eyes[layout.eyes - 1];
    std::vector<float> out(depth.size(), -1.0f);
    const int w = layout.eyeWidth, h = layout.eyeHeight;
    for (int y = 0; y < h && size_t(y) * w < depth.size(); ++y)
        for (int x = 0; x < w; ++x) {
            const float d = depth[size_t(y) * w + x];
            if (d >= 1.0f) continue;
            // Rows are top to bottom; NDC y grows upwards.
            const Eigen::Vector4f ndc(2.0f * (x + 0.5f) / w - 1.0f, 1.0f - 2.0f * (y + 0.5f) / h, 2.0f * d - 1.0f,
                                      1.0f);
            const Eigen::Vector4f p = e.inverseViewProjection * ndc;
            out[size_t(y) * w + x] = (p.head<3>() / p.w() - point).norm();
        }
    return out;
}

} // namespace viscera::render
