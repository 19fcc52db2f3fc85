#pragma once
/// The one interface every renderer backend implements: OpenGL 4.x (gl/gl_backend.cpp; a window's
/// context or a headless EGL one) and the mock (records passes and uploads; no GL) for tests.
/// The Renderer decides what runs; a backend only executes passes.
#include "render/area_light.hpp"
#include "render/camera.hpp"
#include "render/frame_plan.hpp"
#include "render/image.hpp"
#include "render/scene_view.hpp"
#include "render/settings.hpp"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace viscera::render {

/// Everything a pass may read besides its input target.
struct PassContext {
    const RenderSettings& settings;
    const SceneView& view;
    const EyeView& eye;
    const EyeView& previousEye; ///< same eye, last frame (velocity)
    const LightFrame& light;
    int frameIndex = 0;
};

/// Counters a test can check (e.g. "meshes update without reallocating buffers").
struct BackendStats {
    uint64_t bufferAllocations = 0; ///< GPU buffers created or resized
    uint64_t bufferUpdates = 0;     ///< in-place sub-data writes
    uint64_t targetAllocations = 0; ///< render-target (re)allocations
    uint64_t drawCalls = 0;
    uint64_t passesRun = 0;
    uint64_t textureUploads = 0; ///< material map images sent to the GPU (once per map and material)
    uint64_t mappedDraws = 0;    ///< G-buffer draws that sampled material maps
};

enum class ImageStage : uint8_t {
    Final,      ///< what the frame shows (after post effects, stereo composition)
    Unprocessed ///< the lit image of the last eye encoded like Output, no post effect
};

class Backend {
public:
    virtual ~Backend() = default;
    virtual const char* name() const = 0;
    /// (Re)allocates targets when the layout changed; no-op otherwise.
    virtual void resize(const FrameLayout& layout) = 0;
    /// Creates GPU buffers for mesh `index` of the view, sized once.
    virtual void createMesh(size_t index, const RenderMesh& mesh) = 0;
    /// Writes the per-frame data (and static attributes when `staticChanged`) into the buffers
    /// created by createMesh, without reallocating them.
    virtual void updateMesh(size_t index, const RenderMesh& mesh, bool staticChanged) = 0;
    /// Writes the indices of the faces `mesh.faceMask` keeps (all when empty), compacted, into the
    /// index buffer created by createMesh and draws only those from then on [A §5.3.1]. No
    /// reallocation.
    virtual void updateFaceMask(size_t index, const RenderMesh& mesh) = 0;
    virtual void runPass(const PassDesc& pass, const PassContext& context) = 0;
    /// Blocks until submitted work is done (pass timing).
    virtual void finish() = 0;
    virtual Image readPixels(ImageStage stage) = 0;
    /// Window-space depth in [0, 1] of the last eye's G-buffer, eye-sized, rows top to bottom.
    virtual std::vector<float> readDepth() = 0;
    /// Copies Final into a framebuffer of the current context (a window's; 0 = default).
    virtual void present(uint32_t framebuffer, int width, int height) = 0;
    virtual BackendStats stats() const = 0;
    /// Renderer/driver string ("llvmpipe (LLVM 15.0.6, 256 bits)", "mock").
    virtual std::string deviceName() const = 0;
};

/// Records every call; readPixels returns a blank image of the output size.
class MockBackend final : public Backend {
public:
    struct MeshRecord {
        size_t vertices = 0, triangles = 0;
        uint64_t updates = 0;
        size_t drawnTriangles = 0;          ///< faces the G-buffer pass would draw (face mask)
        uint64_t maskUpdates = 0;           ///< updateFaceMask calls
        std::vector<uint32_t> drawnIndices; ///< what the index buffer holds, compacted
    };
    const char* name() const override { return "mock"; }
    void resize(const FrameLayout& layout) override;
    void createMesh(size_t index, const RenderMesh& mesh) override;
    void updateMesh(size_t index, const RenderMesh& mesh, bool staticChanged) override;
    void updateFaceMask(size_t index, const RenderMesh& mesh) override;
    void runPass(const PassDesc& pass, const PassContext& context) override;
    void finish() override {}
    Image readPixels(ImageStage stage) override;
    std::vector<float> readDepth() override;
    void present(uint32_t, int, int) override { ++m_presents; }
    BackendStats stats() const override { return m_stats; }
    std::string deviceName() const override { return "mock"; }

    const std::vector<PassDesc>& passes() const { return m_passes; }
    void clearPasses() { m_passes.clear(); }
    const std::vector<MeshRecord>& meshes() const { return m_meshes; }
    /// Light sample count the lighting pass would give each visible mesh vertex (from the last
    /// lighting pass): one entry per mesh, one count per vertex.
    const std::vector<std::vector<int>>& lightingSamples() const { return m_samples; }
    FrameLayout layout() const { return m_layout; }

private:
    FrameLayout m_layout;
    BackendStats m_stats;
    std::vector<PassDesc> m_passes;
    std::vector<MeshRecord> m_meshes;
    std::vector<std::vector<int>> m_samples;
    int m_presents = 0;
};

/// Loader for GL entry points of the current context (eglGetProcAddress, QOpenGLContext::…).
using GlProcLoader = void* (*)(const char* name, void* user);

/// OpenGL 4.1+ core backend on the context current on this thread. Returns nullptr and sets
/// `whyNot` when the context is unusable (version too old, missing entry points, shader errors).
std::unique_ptr<Backend> createGlBackend(GlProcLoader loader, void* user, std::string* whyNot);

} // namespace viscera::render
