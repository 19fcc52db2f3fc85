#pragma once
/// Backend-independent frame driver: keeps GPU meshes in step with a SceneView (created once,
/// updated in place), computes cameras (mono or stereo), places the light, plans the passes of the
/// frame from the settings and runs them on the backend, timing each one.
#include "render/backend.hpp"

#include <array>
#include <memory>
#include <string>
#include <vector>

namespace viscera::render {

struct PassTiming {
    std::string name; ///< passName(), e.g. "lighting"
    int eye = 0;
    double ms = 0; ///< wall time to completion (the backend is waited for after each pass)
};

struct FrameStats {
    int frameIndex = 0;
    double totalMs = 0;  ///< upload + all passes
    double uploadMs = 0; ///< mesh data written this frame
    std::vector<PassTiming> passes;
    /// Sum of the passes with this name over both eyes, ms (0 when it did not run).
    double passMs(const std::string& name) const;
};

class Renderer {
public:
    /// Takes ownership of `backend` (must not be null). Settings are validated.
    Renderer(std::unique_ptr<Backend> backend, const RenderSettings& settings);
    Renderer(const Renderer&) = delete;
    Renderer& operator=(const Renderer&) = delete;

    /// Validates (std::invalid_argument) and applies; takes effect at the next frame.
    void setSettings(const RenderSettings& settings);
    const RenderSettings& settings() const { return m_settings; }

    /// Renders `view` once. New meshes get buffers; changed ones are updated in place. A mesh whose
    /// vertex or index count changed since its buffers were made is skipped and reported in
    /// FrameStats-independent warnings (warnings()). Never throws on per-frame data.
    const FrameStats& renderFrame(const SceneView& view);
    const FrameStats& lastFrame() const { return m_stats; }

    Image readPixels(ImageStage stage = ImageStage::Final) { return m_backend->readPixels(stage); }
    /// Distance (m) from each pixel's surface point to `point`, eye-sized, rows top to bottom;
    /// negative where the pixel shows background. Uses the last eye of the last frame.
    std::vector<float> distanceMap(const Eigen::Vector3f& point);
    /// Presents the last frame into a framebuffer of the current context (window mode).
    void present(uint32_t framebuffer, int width, int height) { m_backend->present(framebuffer, width, height); }

    /// Eye matrices of the last frame (0 = mono or left, 1 = right) and the placed light.
    const EyeView& eye(int i) const { return m_eyes[i]; }
    const LightFrame& light() const { return m_light; }
    Backend& backend() { return *m_backend; }
    const std::vector<std::string>& warnings() const { return m_warnings; }

private:
    struct MeshState {
        size_t vertices = 0, indices = 0;
        uint64_t revision = ~uint64_t(0), staticRevision = ~uint64_t(0);
        uint64_t faceMaskRevision = 0;
        bool broken = false;
    };
    void syncMeshes(const SceneView& view);

    std::unique_ptr<Backend> m_backend;
    RenderSettings m_settings;
    std::vector<MeshState> m_meshes;
    std::array<EyeView, 2> m_eyes{}, m_previousEyes{};
    LightFrame m_light;
    FrameStats m_stats;
    int m_frame = 0;
    std::vector<std::string> m_warnings;
};

} // namespace viscera::render
