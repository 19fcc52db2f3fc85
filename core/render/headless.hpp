#pragma once
/// Headless rendering through EGL (Mesa surfaceless platform or a pbuffer; llvmpipe where there is
/// no GPU) — what the player's `--headless --screenshot` and the golden-image tests use — and the
/// entry point for a window's context (studio QOpenGLWidget, player window).
#include "render/renderer.hpp"

#include <filesystem>
#include <memory>
#include <string>

namespace viscera::sim {
class World;
}

namespace viscera::render {

class HeadlessRenderer {
public:
    /// Creates an EGL context and an OpenGL backend. Returns nullptr and sets `whyNot` (one line:
    /// "EGL: no display could be initialised (EGL error 0x3001)") when no context can be made.
    /// Throws std::invalid_argument on invalid settings.
    static std::unique_ptr<HeadlessRenderer> create(const RenderSettings& settings, std::string* whyNot = nullptr);
    ~HeadlessRenderer();
    HeadlessRenderer(const HeadlessRenderer&) = delete;
    HeadlessRenderer& operator=(const HeadlessRenderer&) = delete;

    /// Renders one frame; the returned stats hold the per-pass timings (ms).
    const FrameStats& renderFrame(const SceneView& view);
    Image readPixels(ImageStage stage = ImageStage::Final);
    /// Reads the last frame and writes it as PNG. Throws std::runtime_error naming the path.
    void writePng(const std::filesystem::path& path, ImageStage stage = ImageStage::Final);

    Renderer& renderer() { return *m_renderer; }
    const FrameStats& lastFrame() const { return m_renderer->lastFrame(); }
    void setSettings(const RenderSettings& s) { m_renderer->setSettings(s); }
    const RenderSettings& settings() const { return m_renderer->settings(); }
    /// "llvmpipe (LLVM 15.0.6, 256 bits) — EGL 1.5 (surfaceless), OpenGL 4.5 core".
    std::string description() const;

private:
    struct Impl;
    HeadlessRenderer() = default;
    std::unique_ptr<Impl> m_impl;
    std::unique_ptr<Renderer> m_renderer;
};

/// True when a headless OpenGL context can be created here; `whyNot` says why not.
bool headlessContextAvailable(std::string* whyNot = nullptr);

/// Renderer on the OpenGL context current on this thread (a window's): `loader` resolves GL entry
/// points (e.g. QOpenGLContext::getProcAddress wrapped in a function). Present with
/// Renderer::present(framebuffer, width, height). Returns nullptr and sets `whyNot` on failure.
std::unique_ptr<Renderer> createRendererForCurrentContext(GlProcLoader loader, void* user,
                                                          const RenderSettings& settings,
                                                          std::string* whyNot = nullptr);

/// Settings that frame `view` from above and in front, with the scope light on the camera.
RenderSettings defaultSettingsFor(const SceneView& view, int width = 640, int height = 480);

/// One-call screenshot of a world: builds a SceneView, renders one frame headless and writes a PNG.
/// `settings` null: defaultSettingsFor(view). Returns the frame's stats. Throws std::runtime_error
/// (no GL context, PNG not writable) naming the cause.
FrameStats screenshotWorld(const sim::World& world, const std::filesystem::path& path,
                           const RenderSettings* settings = nullptr);

} // namespace viscera::render
