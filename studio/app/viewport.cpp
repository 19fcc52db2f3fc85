#include "app/viewport.hpp"

#include "app/paint_overlays.hpp"
#include "render/camera.hpp"
#include "render/case_settings.hpp"
#include "render/headless.hpp"

#include <Eigen/Geometry>
#include <QCoreApplication>
#include <QElapsedTimer>
#include <QMouseEvent>
#include <QOffscreenSurface>
#include <QOpenGLContext>
#include <QOpenGLFramebufferObject>
#include <QOpenGLFunctions>
#include <QOpenGLWidget>
#include <QPlatformSurfaceEvent>
#include <QPointer>
#include <QThread>
#include <QVBoxLayout>
#include <QWheelEvent>
#include <QWindow>

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <future>
#include <limits>
#include <mutex>

namespace viscera::studio {
namespace {

void* resolve(const char* name, void* user) {
    auto* ctx = static_cast<QOpenGLContext*>(user);
    return reinterpret_cast<void*>(ctx->getProcAddress(name));
}

/// Möller–Trumbore; t of the hit or +inf.
float hitTriangle(const Eigen::Vector3f& o, const Eigen::Vector3f& d, const Eigen::Vector3f& a,
                  const Eigen::Vector3f& b, const Eigen::Vector3f& c) {
    const Eigen::Vector3f e1 = b - a, e2 = c - a, p = d.cross(e2);
    const float det = e1.dot(p);
    if (std::abs(det) < 1e-14f) return INFINITY;
    const float inv = 1.0f / det;
    const Eigen::Vector3f s = o - a;
    const float u = s.dot(p) * inv;
    if (u < 0 || u > 1) return INFINITY;
    const Eigen::Vector3f q = s.cross(e1);
    const float v = d.dot(q) * inv;
    if (v < 0 || u + v > 1) return INFINITY;
    const float t = e2.dot(q) * inv;
    return t > 0 ? t : INFINITY;
}

} // namespace

struct ViewportFrame {
    std::shared_ptr<const render::SceneView> view;
    uint64_t sceneSerial = 0; ///< a new scene gets new GPU buffers: a fresh renderer
    uint64_t lookSerial = 0;  ///< the case's render block changed: settings made again
    std::string caseRender;
    render::Camera camera;
    bool authoring = true; ///< the authoring look (Viewport::Look)
};

namespace {

/// Draws frames on whatever context is current: the renderer, its resolution scale and the
/// figures the viewport reports. One per host; used by one thread at a time.
class FrameRenderer {
public:
    struct Figures {
        QString info;
        bool ready = false;
        double lastMs = 0, scale = 1.0;
        uint64_t paints = 0;
    };

    /// Renders `f` into framebuffer `fbo` of `w`×`h` device pixels with `ctx` current; `onScreen`:
    /// a frame on screen, which counts and drives the resolution scale (a grab does not).
    /// Returns the failure to report when the renderer could not be made (once), else empty.
    QString render(QOpenGLContext* ctx, const ViewportFrame& f, unsigned fbo, int w, int h, bool onScreen) {
        QString failed;
        if (!m_renderer || f.sceneSerial != m_scene) {
            std::string why;
            render::RenderSettings s; // made for the scene below
            s.width = w;
            s.height = h;
            try {
                m_renderer = render::createRendererForCurrentContext(resolve, ctx, s, &why);
            } catch (const std::exception& e) {
                m_renderer.reset();
                why = e.what();
            }
            m_scene = f.sceneSerial;
            m_look = ~uint64_t(0);
            std::lock_guard lock(m_mutex);
            m_figures.ready = m_renderer != nullptr;
            if (m_renderer) {
                m_figures.info = QString::fromStdString(m_renderer->backend().deviceName());
            } else {
                m_figures.info = QObject::tr("viewport: no renderer (%1)").arg(QString::fromStdString(why));
                if (!m_reportedFailure) failed = m_figures.info;
                m_reportedFailure = true;
            }
        }
        QOpenGLFunctions* gl = ctx->functions();
        if (!m_renderer || !f.view || f.view->meshes().empty()) {
            gl->glBindFramebuffer(GL_FRAMEBUFFER, fbo); // nothing to draw (yet)
            gl->glClearColor(0.05f, 0.02f, 0.02f, 1.0f);
            gl->glClear(GL_COLOR_BUFFER_BIT);
            return failed;
        }
        QElapsedTimer timer;
        timer.start();
        const double scale = figures().scale;
        const int rw = std::max(1, static_cast<int>(w * scale)), rh = std::max(1, static_cast<int>(h * scale));
        render::RenderSettings s = m_renderer->settings();
        QString note;
        if (s.width != rw || s.height != rh || f.lookSerial != m_look) {
            render::RenderSettings d = render::defaultSettingsFor(*f.view, rw, rh);
            try {
                render::applyCaseRender(d, f.caseRender, "project.json");
            } catch (const std::exception& e) {
                note = QObject::tr("viewport: %1").arg(QString::fromStdString(e.what())); // load checked it already
            }
            d.stereo.mode = render::StereoMode::Off; // the author's view is mono
            d.timePasses = false;
            if (f.authoring) { // flat and plain: the shapes, not the trainee's look
                d.post.disableAll();
                d.subsurface = false;
                d.ambient = Eigen::Vector3f(0.22f, 0.22f, 0.22f);
                d.background = Eigen::Vector3f(0.16f, 0.17f, 0.19f);
            }
            s = d;
            m_look = f.lookSerial;
        }
        s.camera = f.camera;
        s.light.followCamera = true;
        try {
            m_renderer->setSettings(s);
            m_renderer->renderFrame(*f.view);
            m_renderer->present(fbo, w, h); // scaled up when rendered smaller
        } catch (const std::exception& e) {
            note = QObject::tr("viewport: %1").arg(QString::fromStdString(e.what()));
        }
        if (onScreen) gl->glFinish(); // the frame's cost includes the rasterization
        const double ms = timer.nsecsElapsed() * 1e-6;
        std::lock_guard lock(m_mutex);
        if (!note.isEmpty()) m_figures.info = note;
        if (!onScreen) return failed;
        ++m_figures.paints;
        m_figures.lastMs = ms;
        // resolution follows the paint budget (the cost scales with the pixel count, ~scale²)
        double& sc = m_figures.scale;
        if (ms > Viewport::kPaintBudgetMs && sc > Viewport::kMinScale)
            sc = std::max(Viewport::kMinScale, sc * std::sqrt(Viewport::kPaintBudgetMs / ms) * 0.9);
        else if (ms < 0.4 * Viewport::kPaintBudgetMs && sc < 1.0)
            sc = std::min(1.0, sc * 1.25);
        return failed;
    }

    /// With the renderer's context current.
    void release() { m_renderer.reset(); }

    Figures figures() const {
        std::lock_guard lock(m_mutex);
        return m_figures;
    }

private:
    std::unique_ptr<render::Renderer> m_renderer;
    uint64_t m_scene = ~uint64_t(0), m_look = ~uint64_t(0);
    bool m_reportedFailure = false;
    mutable std::mutex m_mutex;
    Figures m_figures;
};

} // namespace

class ViewportCanvas {
public:
    virtual ~ViewportCanvas() = default;
    /// Draws the viewport's current frame soon (never waits for it on the Window host).
    virtual void schedule() = 0;
    /// Renders the current frame offscreen and reads it back (null: nothing to read).
    virtual QImage grab() = 0;
    /// Ends drawing and releases the GL objects (before the viewport goes).
    virtual void shutdown() = 0;
    FrameRenderer::Figures figures() const { return m_frames.figures(); }

protected:
    explicit ViewportCanvas(Viewport* owner) : m_owner(owner) {}
    ViewportFrame frame() { return m_owner->frame(); }
    /// Hands a mouse, wheel or key event of the host to the Viewport's handlers.
    bool deliver(QEvent* e) { return m_owner->event(e); }
    /// Emits rendererFailed on the UI thread (from any thread).
    void reportFailure(const QString& why) {
        if (why.isEmpty()) return;
        QPointer<Viewport> v(m_owner);
        QMetaObject::invokeMethod(
            m_owner,
            [v, why] {
                if (v) emit v->rendererFailed(why);
            },
            Qt::QueuedConnection);
    }
    static QImage grabInto(FrameRenderer& frames, QOpenGLContext* ctx, const ViewportFrame& f, QSize px) {
        QOpenGLFramebufferObject fbo(px, QOpenGLFramebufferObject::CombinedDepthStencil);
        if (!fbo.isValid()) return {};
        frames.render(ctx, f, fbo.handle(), px.width(), px.height(), false);
        return fbo.toImage();
    }

    Viewport* m_owner;
    FrameRenderer m_frames;
};

namespace {

constexpr int kRenderNice = 3; ///< below the UI thread (0), above the preview's physics (5)

/// Mesa's software rasterizer (llvmpipe) draws with worker threads of its own, started at the
/// UI thread's priority when Qt made its first context. They are the viewport's work: they get
/// the render thread's priority, so that on a machine without a GPU a frame yields to the UI
/// thread instead of competing with it. Other drivers have no such threads; nothing changes.
void yieldSoftwareRasterizer() {
    std::error_code ec;
    for (const auto& task : std::filesystem::directory_iterator("/proc/self/task", ec)) {
        std::ifstream comm(task.path() / "comm");
        std::string name;
        if (!std::getline(comm, name) || name.rfind("llvmpipe-", 0) != 0) continue;
        const long tid = std::strtol(task.path().filename().c_str(), nullptr, 10);
        if (tid > 0) ::setpriority(PRIO_PROCESS, static_cast<id_t>(tid), kRenderNice);
    }
}

QSize devicePixels(QSize logical, qreal dpr) {
    return {std::max(1, static_cast<int>(logical.width() * dpr)),
            std::max(1, static_cast<int>(logical.height() * dpr))};
}

/// The default host: a native child window drawn by a render thread with its own context. The
/// UI thread posts the newest frame and returns; the thread draws the newest frame it has,
/// skipping any that were replaced meanwhile.
class WindowCanvas final : public QWindow, public ViewportCanvas {
public:
    explicit WindowCanvas(Viewport* owner) : ViewportCanvas(owner) {
        setSurfaceType(QSurface::OpenGLSurface);
        setFormat(QSurfaceFormat::defaultFormat());
        // The context is made here, on the UI thread (Qt's GLX integration makes its first
        // context's helpers on the GUI thread only), and then handed to the render thread.
        m_context = std::make_unique<QOpenGLContext>();
        m_context->setFormat(QSurfaceFormat::defaultFormat());
        m_created = m_context->create();
        // for releasing the GL objects when the window's surface is gone
        m_offscreen = std::make_unique<QOffscreenSurface>();
        m_offscreen->setFormat(m_context->format());
        m_offscreen->create();
        m_thread.reset(QThread::create([this] { run(); }));
        m_thread->setObjectName("viewportRender");
        m_context->moveToThread(m_thread.get());
        m_thread->start();
    }
    ~WindowCanvas() override { shutdown(); }

    void schedule() override {
        if (!isExposed()) return; // drawn on exposure
        post(frame(), devicePixels(size(), devicePixelRatio()));
    }

    QImage grab() override {
        if (!isExposed()) return {};
        std::future<QImage> image;
        {
            std::lock_guard lock(m_mutex);
            if (m_quit) return {};
            m_grab.emplace();
            image = m_grab->get_future();
            m_grabFrame = frame();
            m_grabSize = devicePixels(size(), devicePixelRatio());
        }
        m_wake.notify_one();
        return image.get();
    }

    void shutdown() override {
        {
            std::lock_guard lock(m_mutex);
            if (m_quit) return;
            m_quit = true;
        }
        m_wake.notify_one();
        m_thread->wait();
    }

protected:
    void exposeEvent(QExposeEvent*) override { schedule(); }
    void resizeEvent(QResizeEvent*) override { schedule(); }
    bool event(QEvent* e) override {
        switch (e->type()) {
        case QEvent::PlatformSurface:
            // The UI thread makes and destroys the native window (showing, reparenting,
            // closing): the render thread never draws on a surface being destroyed.
            setSurfaceUsable(static_cast<QPlatformSurfaceEvent*>(e)->surfaceEventType() ==
                             QPlatformSurfaceEvent::SurfaceCreated);
            return QWindow::event(e);
        case QEvent::MouseButtonPress:
        case QEvent::MouseButtonRelease:
        case QEvent::MouseMove:
        case QEvent::Wheel:
        case QEvent::KeyPress:
            return deliver(e);
        default:
            return QWindow::event(e);
        }
    }

private:
    /// false: waits until the render thread is off the surface; it then leaves it alone until
    /// the surface is made again.
    void setSurfaceUsable(bool usable) {
        std::unique_lock lock(m_mutex);
        m_surfaceUsable = usable;
        m_idle.wait(lock, [&] { return !m_onSurface; });
    }

    void post(ViewportFrame f, QSize px) {
        {
            std::lock_guard lock(m_mutex);
            m_next = std::move(f);
            m_nextSize = px;
        }
        m_wake.notify_one();
    }

    void run() {
        // a frame yields to the UI thread and stays ahead of the preview's physics
        ::setpriority(PRIO_PROCESS, static_cast<id_t>(::gettid()), kRenderNice);
        bool yielded = false;
        QOpenGLContext& ctx = *m_context;
        const bool created = m_created;
        for (;;) {
            std::optional<ViewportFrame> f, grabFrame;
            std::optional<std::promise<QImage>> grab;
            QSize px, grabPx;
            {
                std::unique_lock lock(m_mutex);
                m_wake.wait(lock, [&] { return m_quit || m_next || m_grab; });
                if (m_quit) break;
                std::swap(f, m_next);
                px = m_nextSize;
                std::swap(grab, m_grab);
                std::swap(grabFrame, m_grabFrame);
                grabPx = m_grabSize;
                m_onSurface = m_surfaceUsable;
            }
            if (!m_onSurface || !created || !ctx.makeCurrent(this)) {
                if (m_onSurface) reportFailure(failOnce(tr("viewport: no OpenGL context for the viewport window")));
                if (grab) grab->set_value({});
                leaveSurface();
                continue;
            }
            if (f) {
                reportFailure(m_frames.render(&ctx, *f, ctx.defaultFramebufferObject(), px.width(), px.height(), true));
                ctx.swapBuffers(this);
                if (!yielded) yieldSoftwareRasterizer(); // its threads exist once a frame was drawn
                yielded = true;
            }
            if (grab) grab->set_value(grabInto(m_frames, &ctx, *grabFrame, grabPx));
            ctx.doneCurrent();
            leaveSurface();
        }
        std::optional<std::promise<QImage>> grab;
        {
            std::lock_guard lock(m_mutex);
            std::swap(grab, m_grab);
        }
        if (grab) grab->set_value({});
        if (created && ctx.makeCurrent(m_offscreen.get())) {
            m_frames.release(); // GL objects go with this thread's context
            ctx.doneCurrent();
        }
        ctx.moveToThread(QCoreApplication::instance()->thread()); // deleted with the window
    }

    void leaveSurface() {
        {
            std::lock_guard lock(m_mutex);
            m_onSurface = false;
        }
        m_idle.notify_all();
    }

    QString failOnce(const QString& why) {
        if (m_failed) return {};
        m_failed = true;
        return why;
    }

    std::unique_ptr<QOpenGLContext> m_context;
    std::unique_ptr<QOffscreenSurface> m_offscreen;
    bool m_created = false;
    std::unique_ptr<QThread> m_thread;
    std::mutex m_mutex;
    std::condition_variable m_wake, m_idle;
    bool m_quit = false, m_failed = false;
    bool m_surfaceUsable = false, m_onSurface = false; ///< guarded by m_mutex
    std::optional<ViewportFrame> m_next, m_grabFrame;
    QSize m_nextSize, m_grabSize;
    std::optional<std::promise<QImage>> m_grab;
};

/// The compatibility host, painting on the UI thread. Its input events are not handled here, so
/// Qt passes them on to the parent Viewport.
class WidgetCanvas final : public QOpenGLWidget, public ViewportCanvas {
public:
    explicit WidgetCanvas(Viewport* owner) : QOpenGLWidget(owner), ViewportCanvas(owner) {
        setFocusPolicy(Qt::NoFocus);
    }
    ~WidgetCanvas() override { shutdown(); }
    void schedule() override { update(); }
    QImage grab() override {
        if (!context()) return {};
        makeCurrent();
        QImage img = grabInto(m_frames, context(), frame(), devicePixels(size(), devicePixelRatioF()));
        doneCurrent();
        return img;
    }
    void shutdown() override {
        if (!context()) return;
        makeCurrent();
        m_frames.release(); // GL objects go with the widget's context
        doneCurrent();
    }

protected:
    void paintGL() override {
        const QSize px = devicePixels(size(), devicePixelRatioF());
        reportFailure(m_frames.render(context(), frame(), defaultFramebufferObject(), px.width(), px.height(), true));
    }
};

} // namespace

std::optional<ViewportHost> viewportHostFromText(const QString& text) {
    if (text == "window") return ViewportHost::Window;
    if (text == "widget") return ViewportHost::Widget;
    return std::nullopt;
}

QString viewportHostText(ViewportHost host) {
    return host == ViewportHost::Window ? QStringLiteral("window") : QStringLiteral("widget");
}

Viewport::Viewport(ViewportHost host, QWidget* parent) : QWidget(parent), m_host(host) {
    setFocusPolicy(Qt::StrongFocus);
    setMinimumSize(320, 240);
    auto* layout = new QVBoxLayout(this);
    layout->setContentsMargins(0, 0, 0, 0);
    if (host == ViewportHost::Window) {
        auto* window = new WindowCanvas(this);
        QWidget* container = QWidget::createWindowContainer(window, this); // takes the window
        container->setObjectName("viewportCanvas");
        container->setFocusPolicy(Qt::NoFocus);
        layout->addWidget(container);
        m_canvas = window;
    } else {
        auto* widget = new WidgetCanvas(this);
        widget->setObjectName("viewportCanvas");
        layout->addWidget(widget);
        m_canvas = widget;
    }
}

Viewport::~Viewport() {
    m_canvas->shutdown(); // before the host's window or widget goes with the children
}

QWindow* Viewport::canvasWindow() const {
    return m_host == ViewportHost::Window ? static_cast<WindowCanvas*>(m_canvas) : nullptr;
}

QWidget* Viewport::canvasWidget() const {
    return m_host == ViewportHost::Widget ? static_cast<WidgetCanvas*>(m_canvas) : nullptr;
}

QString Viewport::rendererInfo() const {
    return m_canvas->figures().info;
}
bool Viewport::rendererReady() const {
    return m_canvas->figures().ready;
}
double Viewport::lastPaintMs() const {
    return m_canvas->figures().lastMs;
}
double Viewport::renderScale() const {
    return m_canvas->figures().scale;
}
uint64_t Viewport::paintCount() const {
    return m_canvas->figures().paints;
}

ViewportFrame Viewport::frame() {
    if (!m_published) {
        auto view = std::make_shared<render::SceneView>(m_view);
        for (const render::RenderMesh& m : m_authoring)
            view->meshes().push_back(m);
        if (m_look == Look::Authoring)
            for (const render::RenderMesh& m : m_guides)
                view->meshes().push_back(m);
        m_published = std::move(view);
    }
    ViewportFrame f;
    f.view = m_published;
    f.sceneSerial = m_sceneSerial;
    f.lookSerial = m_lookSerial;
    f.caseRender = m_caseRender;
    f.camera = m_camera;
    f.authoring = m_look == Look::Authoring;
    return f;
}

void Viewport::viewChanged() {
    m_published.reset(); // the next frame takes a new snapshot
    requestFrame();
}

void Viewport::requestFrame() {
    m_canvas->schedule();
}

QImage Viewport::grabFramebuffer() {
    return m_canvas->grab();
}

void Viewport::setScene(const render::SceneView& view) {
    m_view = view;
    ++m_sceneSerial;
    m_baseMaterial.clear();
    const size_t base = m_view.materials().size();
    for (size_t i = 0; i < base; ++i) {
        render::TissueMaterial h = m_view.materials()[i];
        h.surface.colour = 0.5f * h.surface.colour + Eigen::Vector3f(0.25f, 0.3f, 0.45f);
        h.name += " (selected)";
        m_view.addMaterial(h);
    }
    for (const render::RenderMesh& m : m_view.meshes())
        m_baseMaterial.push_back(m.material);
    if (!m_framed) frameAll();
    applyRestPose();
    setSelectedName(m_selected); // hands the new view over (and makes the guides)
}

void Viewport::setLook(Look look) {
    if (look == m_look) return;
    m_look = look;
    ++m_lookSerial;  // settings are made again on the next frame
    ++m_sceneSerial; // the guides come or go: other meshes
    viewChanged();
}

void Viewport::rebuildGuides() {
    m_guides.clear();
    if (m_view.meshes().empty()) return;
    const auto [lo, hi] = m_view.bounds();
    if (!lo.allFinite() || !hi.allFinite()) return;
    m_guides.push_back(gridMesh(lo.cast<double>(), hi.cast<double>(), 0));
    for (const render::RenderMesh& m : m_view.meshes()) {
        if (m_selected.isEmpty() || QString::fromStdString(m.name) != m_selected) continue;
        Eigen::Vector3d a = Eigen::Vector3d::Constant(INFINITY), b = -a;
        for (size_t v = 0; v < m.vertexCount(); ++v) {
            const Eigen::Vector3d p(m.rest[3 * v], m.rest[3 * v + 1], m.rest[3 * v + 2]);
            a = a.cwiseMin(p);
            b = b.cwiseMax(p);
        }
        if (a.allFinite() && b.allFinite()) m_guides.push_back(boxOutlineMesh(a, b, 0));
    }
    ++m_guideRevision; // new values in the buffers the guides have: the renderer uploads them again
    for (render::RenderMesh& m : m_guides) {
        m.revision = m_guideRevision;
        m.staticRevision = m_guideRevision;
    }
}

void Viewport::setCaseRender(const std::string& json) {
    if (json == m_caseRender) return;
    m_caseRender = json;
    ++m_lookSerial; // settings are made again on the next frame
    requestFrame();
}

void Viewport::setPositions(const std::vector<std::vector<Eigen::Vector3d>>& bodies,
                            const std::vector<std::vector<Eigen::Vector3d>>& surfaces) {
    auto& meshes = m_view.meshes();
    for (size_t i = 0; i < meshes.size(); ++i) {
        render::RenderMesh& m = meshes[i];
        const std::vector<Eigen::Vector3d>* src = nullptr;
        if (m.source == render::RenderMesh::Source::Body && m.sourceIndex < bodies.size()) src = &bodies[m.sourceIndex];
        if (m.source == render::RenderMesh::Source::Surface && m.sourceIndex < surfaces.size())
            src = &surfaces[m.sourceIndex];
        if (!src) continue;
        if (m.source == m_restSource && static_cast<int>(m.sourceIndex) == m_restBody) continue;
        bool ok = true;
        for (size_t v = 0; v < m.sourceVertex.size() && ok; ++v)
            ok = m.sourceVertex[v] >= 0 && static_cast<size_t>(m.sourceVertex[v]) < src->size() &&
                 (*src)[m.sourceVertex[v]].allFinite();
        if (!ok) continue; // never draw a non-finite or mismatched state
        for (size_t v = 0; v < m.sourceVertex.size(); ++v) {
            const Eigen::Vector3d& p = (*src)[m.sourceVertex[v]];
            m.positions[3 * v] = static_cast<float>(p.x());
            m.positions[3 * v + 1] = static_cast<float>(p.y());
            m.positions[3 * v + 2] = static_cast<float>(p.z());
        }
        m_view.recomputeNormals(i);
    }
    viewChanged();
}

void Viewport::setSelectedName(const QString& name) {
    m_selected = name;
    auto& meshes = m_view.meshes();
    const size_t base = m_view.materials().size() / 2;
    for (size_t i = 0; i < meshes.size() && i < m_baseMaterial.size(); ++i)
        meshes[i].material = m_baseMaterial[i] + (QString::fromStdString(meshes[i].name) == name && base ? base : 0);
    const size_t guides = m_guides.size();
    rebuildGuides();
    if (m_guides.size() != guides) ++m_sceneSerial; // other meshes: new buffers
    viewChanged();
}

void Viewport::frameAll() {
    if (m_view.meshes().empty()) return;
    const auto [lo, hi] = m_view.bounds();
    if (!lo.allFinite() || !hi.allFinite()) return;
    m_target = 0.5f * (lo + hi);
    const float radius = std::max(0.5f * (hi - lo).norm(), 1e-3f);
    m_distance = radius / std::sin(0.5f * 55.0f * 3.14159265f / 180.0f) * 1.1f;
    m_framed = true;
    updateCamera();
    requestFrame();
}

void Viewport::updateCamera() {
    m_pitch = std::clamp(m_pitch, -1.55f, 1.55f);
    m_distance = std::clamp(m_distance, 1e-3f, 100.0f);
    const Eigen::Vector3f dir(std::cos(m_pitch) * std::cos(m_yaw), std::cos(m_pitch) * std::sin(m_yaw),
                              std::sin(m_pitch));
    m_camera.target = m_target;
    m_camera.position = m_target + m_distance * dir;
    m_camera.up = Eigen::Vector3f(0, 0, 1);
    m_camera.nearPlane = std::max(1e-4f, 0.02f * m_distance);
    m_camera.farPlane = 20.0f * m_distance + 1.0f;
}

render::EyeView Viewport::eye() const {
    const float aspect = static_cast<float>(std::max(1, width())) / static_cast<float>(std::max(1, height()));
    return render::monoEye(m_camera, aspect);
}

void Viewport::ray(QPoint pos, Eigen::Vector3f& origin, Eigen::Vector3f& dir) const {
    const render::EyeView eye = this->eye();
    const float nx = 2.0f * (pos.x() + 0.5f) / std::max(1, width()) - 1.0f;
    const float ny = 1.0f - 2.0f * (pos.y() + 0.5f) / std::max(1, height());
    Eigen::Vector4f a = eye.inverseViewProjection * Eigen::Vector4f(nx, ny, -1, 1);
    Eigen::Vector4f b = eye.inverseViewProjection * Eigen::Vector4f(nx, ny, 1, 1);
    origin = a.head<3>() / a.w();
    dir = (b.head<3>() / b.w() - origin).normalized();
}

std::optional<QPointF> Viewport::toScreen(const Eigen::Vector3f& x) const {
    const Eigen::Vector4f c = eye().viewProjection * Eigen::Vector4f(x.x(), x.y(), x.z(), 1);
    if (!(c.w() > 0)) return std::nullopt;
    const float nx = c.x() / c.w(), ny = c.y() / c.w();
    return QPointF(0.5 * (nx + 1) * std::max(1, width()) - 0.5, 0.5 * (1 - ny) * std::max(1, height()) - 0.5);
}

void Viewport::setHandleGrabber(HandleGrabber* grabber) {
    m_grabber = grabber;
    m_handleDrag = false;
}

std::optional<Viewport::SurfaceHit> Viewport::hitAt(QPoint pos) const {
    Eigen::Vector3f o, d;
    ray(pos, o, d);
    float best = INFINITY;
    int bestMesh = -1;
    size_t bestFace = 0;
    const auto& meshes = m_view.meshes();
    auto corner = [](const std::vector<float>& xyz, uint32_t v) {
        return Eigen::Vector3f(xyz[3 * v], xyz[3 * v + 1], xyz[3 * v + 2]);
    };
    // A tissue layer lies on the body it was cut from (the same triangles): within kLayerTie of the
    // body's hit the layer is what the ray meets first.
    constexpr float kLayerTie = 1e-5f; // m
    for (size_t k = 0; k < meshes.size(); ++k) {
        const render::RenderMesh& m = meshes[k];
        if (!m.visible) continue;
        const float tie = m.source == render::RenderMesh::Source::Surface ? kLayerTie : 0.0f;
        for (size_t f = 0; f + 2 < m.indices.size(); f += 3) {
            const float t = hitTriangle(o, d, corner(m.positions, m.indices[f]), corner(m.positions, m.indices[f + 1]),
                                        corner(m.positions, m.indices[f + 2]));
            if (t < best + tie && std::isfinite(t)) {
                best = t;
                bestMesh = static_cast<int>(k);
                bestFace = f;
            }
        }
    }
    if (bestMesh < 0) return std::nullopt;
    const render::RenderMesh& m = meshes[bestMesh];
    SurfaceHit hit;
    hit.mesh = bestMesh;
    hit.name = QString::fromStdString(m.name);
    hit.world = o + best * d;
    // barycentric coordinates on the drawn triangle carry the point to the rest surface
    const Eigen::Vector3f a = corner(m.positions, m.indices[bestFace]),
                          b = corner(m.positions, m.indices[bestFace + 1]),
                          c = corner(m.positions, m.indices[bestFace + 2]);
    const Eigen::Vector3f n = (b - a).cross(c - a);
    const float area = n.squaredNorm();
    float u = 1.0f / 3, v = 1.0f / 3;
    if (area > 0) {
        u = (c - b).cross(hit.world - b).dot(n) / area; // weight of a
        v = (a - c).cross(hit.world - c).dot(n) / area; // weight of b
    }
    if (area > 0) hit.normal = n.normalized();
    hit.rest = u * corner(m.rest, m.indices[bestFace]) + v * corner(m.rest, m.indices[bestFace + 1]) +
               (1 - u - v) * corner(m.rest, m.indices[bestFace + 2]);
    return hit;
}

QString Viewport::pick(QPoint pos) const {
    const auto hit = hitAt(pos);
    return hit ? hit->name : QString();
}

void Viewport::setOverlay(int mesh, const std::vector<float>& rgba) {
    if (mesh < 0 || mesh >= static_cast<int>(m_view.meshes().size())) return;
    m_view.setOverlay(static_cast<size_t>(mesh), rgba);
    viewChanged();
}

void Viewport::setMeshVisible(int mesh, bool visible) {
    if (mesh < 0 || mesh >= static_cast<int>(m_view.meshes().size())) return;
    if (m_view.meshes()[mesh].visible == visible) return;
    m_view.meshes()[mesh].visible = visible;
    viewChanged();
}

void Viewport::setMeshTranslucent(int mesh, bool translucent) {
    if (mesh < 0 || mesh >= static_cast<int>(m_view.meshes().size())) return;
    if (m_view.meshes()[mesh].translucent == translucent) return;
    m_view.meshes()[mesh].translucent = translucent;
    viewChanged();
}

void Viewport::setFaceMask(int mesh, const std::vector<uint8_t>& mask) {
    if (mesh < 0 || mesh >= static_cast<int>(m_view.meshes().size())) return;
    if (m_view.meshes()[mesh].faceMask == mask) return;
    m_view.setFaceMask(static_cast<size_t>(mesh), mask);
    viewChanged();
}

void Viewport::applyRestPose() {
    auto& meshes = m_view.meshes();
    for (size_t i = 0; i < meshes.size(); ++i) {
        render::RenderMesh& m = meshes[i];
        if (m.source != m_restSource || static_cast<int>(m.sourceIndex) != m_restBody) continue;
        m.positions = m.rest;
        m_view.recomputeNormals(i);
    }
}

void Viewport::setRestPose(int index, render::RenderMesh::Source source) {
    if (index == m_restBody && source == m_restSource) return;
    m_restBody = index;
    m_restSource = source;
    applyRestPose(); // back to simulated positions with the preview's next frame
    viewChanged();
}

size_t Viewport::layerStart(Layer layer) const {
    size_t start = 0;
    for (size_t k = 0; k < static_cast<size_t>(layer); ++k)
        start += m_layerSize[k];
    return start;
}

std::vector<render::RenderMesh> Viewport::authoringLayer(Layer layer) const {
    const auto start = static_cast<std::ptrdiff_t>(layerStart(layer));
    const auto size = static_cast<std::ptrdiff_t>(m_layerSize[static_cast<size_t>(layer)]);
    return {m_authoring.begin() + start, m_authoring.begin() + start + size};
}

void Viewport::setAuthoringLayer(Layer layer, std::vector<render::RenderMesh> layerMeshes) {
    const size_t start = layerStart(layer), old = m_layerSize[static_cast<size_t>(layer)];
    if (layerMeshes.empty() && old == 0) return;
    std::vector<render::RenderMesh> meshes(m_authoring.begin(),
                                           m_authoring.begin() + static_cast<std::ptrdiff_t>(start));
    for (render::RenderMesh& m : layerMeshes)
        meshes.push_back(std::move(m));
    meshes.insert(meshes.end(), m_authoring.begin() + static_cast<std::ptrdiff_t>(start + old), m_authoring.end());
    m_layerSize[static_cast<size_t>(layer)] = layerMeshes.size();
    // The same meshes with new values (a stroke recolours the section) are updated in the GPU
    // buffers they have; other meshes need new buffers (a new renderer).
    bool inPlace = meshes.size() == m_authoring.size();
    for (size_t k = 0; k < meshes.size() && inPlace; ++k)
        inPlace = meshes[k].indices == m_authoring[k].indices;
    for (size_t k = 0; k < meshes.size() && inPlace; ++k) {
        meshes[k].revision = m_authoring[k].revision + 1;
        meshes[k].staticRevision = m_authoring[k].staticRevision + 1;
    }
    m_authoring = std::move(meshes);
    if (!inPlace) ++m_sceneSerial;
    viewChanged();
}

void Viewport::setAuthoringMesh(size_t k, render::RenderMesh mesh) {
    if (k >= m_layerSize[static_cast<size_t>(Layer::Paint)]) return;
    render::RenderMesh& old = m_authoring[k];
    const bool inPlace = mesh.indices == old.indices;
    mesh.revision = old.revision + 1;
    mesh.staticRevision = old.staticRevision + 1;
    old = std::move(mesh);
    if (!inPlace) ++m_sceneSerial;
    viewChanged();
}

void Viewport::trackMouse(bool on) {
    setMouseTracking(on); // moves without a button reach the viewport (a window host sends all)
    if (QWidget* w = canvasWidget()) w->setMouseTracking(on);
}

void Viewport::setPaintMode(bool on) {
    if (m_painting && !on) emit paintCancelled();
    if (m_handleDrag && m_grabber) m_grabber->release();
    m_painting = m_handleDrag = false;
    m_paintMode = on;
    trackMouse(on); // the brush outline follows the cursor without a button
    if (!on) emit brushLeft();
    setCursor(on ? Qt::CrossCursor : Qt::ArrowCursor);
}

void Viewport::mousePressEvent(QMouseEvent* e) {
    setFocus(Qt::MouseFocusReason);
    if (m_adjust != Adjust::None) { // the click sets the brush size or strength
        emit brushAdjusted(m_adjust == Adjust::Strength, e->position().x() - m_adjustFrom.x(), true);
        m_adjust = Adjust::None;
        trackMouse(m_paintMode); // the brush outline still follows the cursor
        return;
    }
    m_pressPos = m_lastPos = e->position().toPoint();
    m_button = e->button();
    m_dragged = false;
    if (m_paintMode && m_button == Qt::LeftButton && !(e->modifiers() & Qt::AltModifier)) {
        if (m_grabber && m_grabber->grab(m_pressPos)) {
            m_handleDrag = true;
            return;
        }
        if (auto hit = hitAt(m_pressPos)) {
            m_painting = true;
            hit->invert = (e->modifiers() & Qt::ControlModifier) != 0;
            emit paintPressed(*hit);
        }
        return;
    }
}

void Viewport::mouseMoveEvent(QMouseEvent* e) {
    const QPoint p = e->position().toPoint();
    const QPoint dp = p - m_lastPos;
    m_lastPos = p;
    if (m_adjust != Adjust::None) {
        emit brushAdjusted(m_adjust == Adjust::Strength, p.x() - m_adjustFrom.x(), false);
        return;
    }
    if ((p - m_pressPos).manhattanLength() > 3) m_dragged = true;
    if (m_handleDrag) {
        if (m_grabber) m_grabber->drag(p);
        return;
    }
    if (m_paintMode && (m_button == Qt::NoButton || m_painting)) { // the brush outline follows the cursor
        if (const auto hit = hitAt(p))
            emit brushHovered(*hit);
        else
            emit brushLeft();
    }
    if (m_painting) {
        if (const auto hit = hitAt(p)) emit paintMoved(*hit); // off the surface: no dab
        return;
    }
    const bool pan =
        m_button == Qt::MiddleButton || (m_button == Qt::LeftButton && (e->modifiers() & Qt::ShiftModifier));
    if (pan) {
        const Eigen::Vector3f fwd = (m_camera.target - m_camera.position).normalized();
        const Eigen::Vector3f right = fwd.cross(Eigen::Vector3f(0, 0, 1)).normalized();
        const Eigen::Vector3f up = right.cross(fwd);
        const float scale = 2.0f * m_distance * std::tan(0.5f * 55.0f * 3.14159265f / 180.0f) / std::max(1, height());
        m_target += (-dp.x() * right + dp.y() * up) * scale;
    } else if (m_button == Qt::LeftButton || m_button == Qt::RightButton) {
        // Right drag orbits in every mode (in paint mode the left button paints, and Alt + drag is
        // taken by most Linux window managers).
        m_yaw -= 0.01f * dp.x();
        m_pitch += 0.01f * dp.y();
    } else {
        return;
    }
    updateCamera();
    requestFrame();
}

void Viewport::mouseReleaseEvent(QMouseEvent* e) {
    if (m_handleDrag && e->button() == Qt::LeftButton) {
        m_handleDrag = false;
        m_button = Qt::NoButton;
        if (m_grabber) m_grabber->release();
        return;
    }
    if (m_painting && e->button() == Qt::LeftButton) {
        m_painting = false;
        m_button = Qt::NoButton;
        emit paintReleased();
        return;
    }
    if (m_paintMode && e->button() == Qt::LeftButton) {
        m_button = Qt::NoButton;
        return; // a click in paint mode paints, it does not select
    }
    if (e->button() == Qt::LeftButton && !m_dragged) {
        const QString name = pick(e->position().toPoint());
        if (!name.isEmpty()) emit bodyClicked(name);
    }
    m_button = Qt::NoButton;
}

void Viewport::wheelEvent(QWheelEvent* e) {
    m_distance *= std::pow(0.85f, e->angleDelta().y() / 120.0f);
    updateCamera();
    requestFrame();
    e->accept();
}

void Viewport::keyPressEvent(QKeyEvent* e) {
    if (m_paintMode && e->key() == Qt::Key_F && !m_painting) {
        m_adjust = e->modifiers() & Qt::ShiftModifier ? Adjust::Strength : Adjust::Radius;
        m_adjustFrom = m_lastPos; // the cursor's last position over the viewport
        trackMouse(true);
        emit brushAdjusted(m_adjust == Adjust::Strength, 0, false);
        return;
    }
    if (e->key() == Qt::Key_Escape && m_adjust != Adjust::None) {
        emit brushAdjusted(m_adjust == Adjust::Strength, 0, true);
        m_adjust = Adjust::None;
        trackMouse(m_paintMode); // the brush outline still follows the cursor
        return;
    }
    if (e->key() == Qt::Key_Escape && m_painting) {
        m_painting = false;
        emit paintCancelled();
        return;
    }
    if (e->key() == Qt::Key_Escape && m_paintMode) {
        emit paintEscaped();
        return;
    }
    if (e->key() == Qt::Key_F || e->key() == Qt::Key_Home) {
        frameAll();
        return;
    }
    QWidget::keyPressEvent(e);
}

} // namespace viscera::studio
