#include "render/headless.hpp"

#include "render/gl/egl_context.hpp"
#include "sim/scene/world.hpp"

#include <limits>
#include <stdexcept>

namespace viscera::render {

struct HeadlessRenderer::Impl {
    std::unique_ptr<gl::EglContext> context;
};

std::unique_ptr<HeadlessRenderer> HeadlessRenderer::create(const RenderSettings& settings, std::string* whyNot) {
    settings.validate();
    std::unique_ptr<HeadlessRenderer> r(new HeadlessRenderer);
    r->m_impl = std::make_unique<Impl>();
    r->m_impl->context = gl::EglContext::create(whyNot);
    if (!r->m_impl->context) return nullptr;
    std::unique_ptr<Backend> backend = createGlBackend(&gl::EglContext::procAddress, nullptr, whyNot);
    if (!backend) return nullptr;
    r->m_renderer = std::make_unique<Renderer>(std::move(backend), settings);
    return r;
}

HeadlessRenderer::~HeadlessRenderer() {
    if (m_impl && m_impl->context) m_impl->context->makeCurrent();
    m_renderer.reset(); // GL objects go while the context is still alive
    m_impl.reset();
}

const FrameStats& HeadlessRenderer::renderFrame(const SceneView& view) {
    m_impl->context->makeCurrent();
    return m_renderer->renderFrame(view);
}

Image HeadlessRenderer::readPixels(ImageStage stage) {
    m_impl->context->makeCurrent();
    return m_renderer->readPixels(stage);
}

void HeadlessRenderer::writePng(const std::filesystem::path& path, ImageStage stage) {
    render::writePng(path, readPixels(stage));
}

std::string HeadlessRenderer::description() const {
    return m_renderer->backend().deviceName() + " — " + m_impl->context->description();
}

bool headlessContextAvailable(std::string* whyNot) {
    auto ctx = gl::EglContext::create(whyNot);
    if (!ctx) return false;
    auto backend = createGlBackend(&gl::EglContext::procAddress, nullptr, whyNot);
    return backend != nullptr;
}

std::unique_ptr<Renderer> createRendererForCurrentContext(GlProcLoader loader, void* user,
                                                          const RenderSettings& settings, std::string* whyNot) {
    settings.validate();
    std::unique_ptr<Backend> backend = createGlBackend(loader, user, whyNot);
    if (!backend) return nullptr;
    return std::make_unique<Renderer>(std::move(backend), settings);
}

RenderSettings defaultSettingsFor(const SceneView& view, int width, int height) {
    RenderSettings s;
    s.width = width;
    s.height = height;
    const auto [lo, hi] = view.bounds();
    // A laparoscope looks at the organ obliquely from above and in front.
    s.camera = frameBounds(lo, hi, Eigen::Vector3f(0.0f, 0.75f, -0.66f), 55.0f, 1.15f);
    const float size = (hi - lo).norm();
    s.light.followCamera = true;
    s.light.cameraOffset = Eigen::Vector3f(0.12f * size, 0.06f * size, 0.0f);
    const float dist = (s.camera.target - s.camera.position).norm();
    s.light.intensity = 0.9f * dist * dist; // irradiance ≈ 0.9 at the target
    s.light.width = 0.1f * size;
    s.light.height = 0.05f * size;
    s.sampling.bands = {{0.8f * dist, 8}, {1.0f * dist, 4}, {std::numeric_limits<float>::infinity(), 1}};
    return s;
}

FrameStats screenshotWorld(const sim::World& world, const std::filesystem::path& path, const RenderSettings* settings) {
    const SceneView view = SceneView::fromWorld(world);
    const RenderSettings s = settings ? *settings : defaultSettingsFor(view);
    std::string why;
    auto renderer = HeadlessRenderer::create(s, &why);
    if (!renderer) throw std::runtime_error("render::screenshotWorld(): no OpenGL context: " + why);
    FrameStats stats = renderer->renderFrame(view);
    renderer->writePng(path);
    return stats;
}

} // namespace viscera::render
