// The trainee window on QtGui (QRasterWindow + QPainter), no Widgets. The 3D view is drawn by the
// deferred renderer on a headless EGL context (the same path as --headless --screenshot) and
// painted into the window; where no GL context can be made, a 2D side view of the nodes is drawn.
#include "window/window_mode.hpp"

#include "haptics/keyboard_device.hpp"
#include "render/case_settings.hpp"
#include "render/headless.hpp"
#include "render/scene_view.hpp"
#include "render/scope_view.hpp"
#include "runtime/keyboard_keys.hpp"
#include "runtime/live_scene.hpp"
#include "runtime/realtime_watch.hpp"
#include "runtime/render_pacer.hpp"
#include "sim/util/atomic_file.hpp"
#include "sim/util/log.hpp"
#include "window/verdict_screen.hpp"

#include <QBuffer>
#include <QElapsedTimer>
#include <QGuiApplication>
#include <QImage>
#include <QKeyEvent>
#include <QMouseEvent>
#include <QPainter>
#include <QRasterWindow>
#include <QTimer>
#include <QWheelEvent>

#include <atomic>
#include <clocale>
#include <cstdlib>
#include <future>
#include <optional>
#include <thread>

#include <pthread.h>
#include <sched.h>

namespace viscera::player {
namespace {

using haptics::KeyboardDevice;

/// The rendered view of the tissue: a SceneView of the world (built before the physics thread
/// starts), refreshed from the LiveView copies of the positions, rendered headless and kept as a
/// QImage for the window's paint events. GUI thread only.
class Viewport3D {
public:
    Viewport3D(const LoadedCase& loaded, LiveView& live, int width, int height) : m_live(live), m_scene(loaded) {
        const sim::World& world = *loaded.world;
        const std::string& caseRender = loaded.scene.render;
        render::RenderSettings settings = render::defaultSettingsFor(m_scene.view(), width, height);
        render::applyCaseRender(settings, caseRender, "scene.json"); // checked at load already
        const render::ToolPoses poses = render::toolPoses(world);
        render::viewThroughScope(settings, poses.scope); // the laparoscope at rest, where the case has one
        m_scene.addTools(poses);                         // after the framing: tissue only
        settings.timePasses = false;                     // one wait per frame: the window shows the total only
        m_renderer = render::HeadlessRenderer::create(settings, &m_whyNot);
        if (m_renderer && softwareGl(m_renderer->description())) {
            // Without a GPU the G-buffer's fragments are most of the frame (llvmpipe, rectum:
            // 51 ms at 640x480, 36 ms at 480x360); the image is scaled to the view anyway.
            settings.width = width * 3 / 4;
            settings.height = height * 3 / 4;
            m_renderer->setSettings(settings);
        }
        if (m_renderer) refresh(); // the rest state, until the first frame arrives
    }
    bool available() const { return m_renderer != nullptr; }
    /// The window's stereo switch: off → side by side → anaglyph → off (the case's mode first).
    void cycleStereo() {
        if (!m_renderer) return;
        render::RenderSettings s = m_renderer->settings();
        using render::StereoMode;
        s.stereo.mode = s.stereo.mode == StereoMode::Off          ? StereoMode::SideBySide
                        : s.stereo.mode == StereoMode::SideBySide ? StereoMode::Anaglyph
                                                                  : StereoMode::Off;
        m_renderer->setSettings(s);
    }
    const char* stereoName() const {
        if (!m_renderer) return "off";
        switch (m_renderer->settings().stereo.mode) {
        case render::StereoMode::SideBySide:
            return "side by side";
        case render::StereoMode::Anaglyph:
            return "anaglyph";
        default:
            return "off";
        }
    }
    const std::string& whyNot() const { return m_whyNot; }
    const QImage& image() const { return m_image; }
    double lastFrameMs() const { return m_frameMs; }

    /// Copies the latest positions, renders one frame (the default passes) and keeps the image.
    void refresh() {
        if (!m_renderer) return;
        {
            // Only the copy holds the view's lock (the physics thread publishes under it every
            // frame); the cut, normals and heat are worked out after.
            std::lock_guard<std::mutex> lock(m_live.mutex);
            m_snap = m_live.geometry;
        }
        m_scene.apply(m_snap);
        if (m_snap.tools.scope.present) { // the camera follows the laparoscope
            render::RenderSettings s = m_renderer->settings();
            render::viewThroughScope(s, m_snap.tools.scope);
            m_renderer->setSettings(s);
        }
        m_frameMs = m_renderer->renderFrame(m_scene.view()).totalMs;
        const render::Image img = m_renderer->readPixels();
        QImage q(img.rgba.data(), img.width, img.height, img.width * 4, QImage::Format_RGBA8888);
        m_image = q.copy(); // own the pixels
    }

private:
    static bool softwareGl(const std::string& device) {
        for (const char* name : {"llvmpipe", "softpipe", "swrast", "SwiftShader"})
            if (device.find(name) != std::string::npos) return true;
        return false;
    }
    LiveView& m_live;
    LiveGeometry m_snap; ///< the last copy of the session's geometry (GUI thread)
    LiveScene m_scene;
    std::unique_ptr<render::HeadlessRenderer> m_renderer;
    std::string m_whyNot;
    QImage m_image;
    double m_frameMs = 0;
};

class TraineeWindow final : public QRasterWindow {
public:
    TraineeWindow(LiveView& live, std::string title, std::string instructions, std::vector<std::string> steps,
                  KeyboardDevice* keyboard, std::atomic<bool>& stop, Viewport3D* viewport)
        : m_live(live), m_title(std::move(title)), m_instructions(std::move(instructions)), m_steps(std::move(steps)),
          m_keyboard(keyboard), m_stop(stop), m_viewport(viewport) {
        setTitle(QString::fromStdString("Viscera — " + m_title));
        resize(960, 600);
    }

    /// The task's steps as a numbered list from baseline `y` in the column at `px` (wrapped, up to
    /// `bottom`); returns the next line's baseline.
    int paintSteps(QPainter& p, int px, int y, int bottom) const {
        if (m_steps.empty()) return y;
        p.setPen(QColor(200, 200, 200));
        p.drawText(px, y, "Steps:");
        y += 20;
        const int ascent = p.fontMetrics().ascent();
        for (size_t k = 0; k < m_steps.size() && y < bottom; ++k) {
            QRect used;
            p.drawText(QRect(px, y - ascent, 236, bottom - y), Qt::AlignLeft | Qt::AlignTop | Qt::TextWordWrap,
                       QString("%1. %2").arg(k + 1).arg(QString::fromStdString(m_steps[k])), &used);
            y += used.height() + 4;
        }
        return y + 8;
    }

    void paintHud(QPainter& p, const QSize& size) {
        LiveState s;
        std::vector<sim::Vec3> nodes;
        std::vector<double> radius;
        std::vector<render::ToolPoses::Instrument> instruments;
        bool scope = false; // the case has a laparoscope (the Cam pedal steers it)
        {
            std::lock_guard<std::mutex> lock(m_live.mutex);
            s = m_live.state;
            if (!m_viewport || !m_viewport->available()) nodes = m_live.geometry.nodes; // the side view only
            radius = m_live.toolRadius;
            instruments = m_live.geometry.tools.instruments;
            scope = m_live.geometry.tools.scope.present;
        }
        const int w = size.width(), h = size.height();
        p.fillRect(0, 0, w, h, QColor(24, 26, 30));
        p.setRenderHint(QPainter::Antialiasing, true);
        // Header: title, timer, instructions.
        QFont big = p.font();
        big.setPointSizeF(16);
        big.setBold(true);
        p.setFont(big);
        p.setPen(QColor(235, 235, 235));
        p.drawText(QRect(16, 8, w - 200, 30), Qt::AlignLeft | Qt::AlignVCenter, QString::fromStdString(m_title));
        const int minutes = static_cast<int>(s.time_s / 60);
        p.drawText(QRect(w - 180, 8, 164, 30), Qt::AlignRight | Qt::AlignVCenter,
                   QString::asprintf("%02d:%04.1f", minutes, s.time_s - 60 * minutes));
        QFont small = p.font();
        small.setPointSizeF(10);
        small.setBold(false);
        p.setFont(small);
        p.setPen(QColor(190, 190, 190));
        p.drawText(QRect(16, 40, w - 32, 40), Qt::AlignLeft | Qt::TextWordWrap, QString::fromStdString(m_instructions));
        // The rendered 3D view; without a GL context a side view (x right, z up) of the tissue
        // nodes and the tools.
        const QRect view(16, 88, w - 280, h - 104);
        p.setPen(QColor(60, 64, 70));
        p.drawRect(view);
        bool sideView = true;
        if (m_viewport && m_viewport->available() && !m_viewport->image().isNull()) {
            const QImage& img = m_viewport->image();
            const QSize fit = img.size().scaled(view.size(), Qt::KeepAspectRatio);
            const QRect target(view.center().x() - fit.width() / 2, view.center().y() - fit.height() / 2, fit.width(),
                               fit.height());
            p.drawImage(target, img);
            p.setPen(QColor(140, 140, 140));
            p.drawText(view.adjusted(6, 0, 0, -4), Qt::AlignLeft | Qt::AlignBottom,
                       QString::asprintf("render %.0f ms", m_viewport->lastFrameMs()));
            sideView = false; // the instruments are in the rendered view
        }
        double x0 = 1e9, x1 = -1e9, z0 = 1e9, z1 = -1e9;
        for (const auto& n : nodes)
            x0 = std::min(x0, n.x()), x1 = std::max(x1, n.x()), z0 = std::min(z0, n.z()), z1 = std::max(z1, n.z());
        for (int a = 0; a < haptics::kMaxArms; ++a)
            if (s.toolActive[a])
                x0 = std::min(x0, s.tool[a].x()), x1 = std::max(x1, s.tool[a].x()), z0 = std::min(z0, s.tool[a].z()),
                z1 = std::max(z1, s.tool[a].z());
        if (sideView && x1 > x0 && z1 >= z0) {
            const double span = std::max(x1 - x0, z1 - z0) * 1.3 + 1e-3;
            const double scale = std::min(view.width(), view.height()) / span;
            const double cx = 0.5 * (x0 + x1), cz = 0.5 * (z0 + z1);
            auto map = [&](const sim::Vec3& v) {
                return QPointF(view.center().x() + (v.x() - cx) * scale, view.center().y() - (v.z() - cz) * scale);
            };
            p.setPen(Qt::NoPen);
            p.setBrush(QColor(214, 120, 110));
            for (const auto& n : nodes)
                p.drawEllipse(map(n), 1.6, 1.6);
            size_t t = 0;
            for (int a = 0; a < haptics::kMaxArms; ++a) {
                if (!s.toolActive[a]) continue;
                const double r = t < radius.size() ? radius[t] : 0.005;
                ++t;
                p.setBrush(QColor(170, 190, 210, 180));
                p.setPen(QColor(220, 230, 240));
                p.drawEllipse(map(s.tool[a]), r * scale, r * scale);
            }
        }
        // Right panel: device, pedals, clutch, force bars, safety.
        const int px = w - 248;
        int y = 96;
        p.setPen(QColor(235, 235, 235));
        p.drawText(px, y, s.connected ? "Device: connected" : "Device: NOT CONNECTED");
        y += 26;
        const char* names[5] = {"Clutch", "Cam", "Dead", "Cut", "Coag"};
        for (int k = 0; k < 5; ++k) {
            const bool on = s.pedals & (1u << k);
            p.setPen(QColor(120, 120, 120));
            p.setBrush(on ? QColor(90, 200, 120) : QColor(50, 54, 60));
            p.drawRect(px + k * 46, y, 42, 22);
            p.setPen(on ? QColor(10, 10, 10) : QColor(200, 200, 200));
            p.drawText(QRect(px + k * 46, y, 42, 22), Qt::AlignCenter, names[k]);
        }
        y += 40;
        p.setPen(QColor(235, 235, 235));
        p.drawText(px, y, (s.pedals & haptics::kPedalClutch) ? "Clutch: ENGAGED (tool holds)" : "Clutch: released");
        y += 20;
        if (m_viewport && m_viewport->available())
            p.drawText(px, y, QString("Stereo: %1 (S switches)").arg(m_viewport->stereoName())), y += 20;
        if ((s.pedals & haptics::kPedalCamera) && scope) {
            p.setPen(QColor(120, 200, 255));
            p.drawText(px, y, "Cam: steering the laparoscope");
            p.setPen(QColor(235, 235, 235));
        }
        y += 8;
        for (int a = 0; a < haptics::kMaxArms; ++a) {
            if (!s.toolActive[a]) continue;
            const double frac = std::clamp(s.force[a] / std::max(1e-9, s.maxForce_n), 0.0, 1.0);
            p.setPen(QColor(235, 235, 235));
            p.drawText(px, y,
                       QString::asprintf("%s %s: force %.2f N", a == 0 ? "Left/1" : "Right/2", s.toolName[a].c_str(),
                                         s.force[a]));
            y += 8;
            p.setPen(QColor(120, 120, 120));
            p.setBrush(QColor(50, 54, 60));
            p.drawRect(px, y, 230, 14);
            p.setBrush(frac < 0.6 ? QColor(90, 200, 120) : frac < 0.85 ? QColor(230, 190, 70) : QColor(230, 80, 70));
            p.drawRect(px, y, static_cast<int>(230 * frac), 14);
            y += 34;
        }
        // Instrument states: jaws, grasp, energy.
        for (const auto& in : instruments) {
            QString state;
            if (in.kind == "energy_hook")
                state = in.act ? "ENERGIZED" : "energy off";
            else if (in.kind == "clip_applier")
                state = in.jaw < 0.2 ? "firing" : in.jaw < 0.5 ? "closing" : "open";
            else
                state = in.grasped > 0 ? QString::asprintf("closed, holding %d", in.grasped)
                        : in.jaw < 0.5 ? "closed"
                                       : "open";
            const bool hot = in.kind == "energy_hook" && in.act;
            p.setPen(hot ? QColor(250, 150, 60) : QColor(200, 200, 200));
            p.drawText(px, y, QString::fromStdString(in.name) + ": " + state);
            y += 20;
        }
        if (!instruments.empty()) y += 8;
        y = paintSteps(p, px, y, h - 100);
        p.setPen(QColor(230, 120, 100));
        if (s.safetyRules & haptics::kRuleSimStale) p.drawText(px, y, "Forces off: simulation stale"), y += 20;
        if (s.safetyRules & haptics::kRuleDisconnected) p.drawText(px, y, "Forces off: device not answering"), y += 20;
        if (s.safetyRules & haptics::kRuleDeadman) p.drawText(px, y, "Forces off: hold the deadman pedal"), y += 20;
        // the estimate's warning, or lag that grew past the limit (now, or earlier: the verdict)
        const std::vector<std::string> notice =
            RealTimeWatch::windowNotice(!s.realTimeWarning.empty(), s.frame, s.lagMs, s.lagGrowthMs, s.lagGrowthMaxMs);
        p.setPen(QColor(230, 80, 60));
        for (size_t k = 0; k < notice.size(); ++k)
            p.drawText(px, h - 76 + 20 * static_cast<int>(k), QString::fromStdString(notice[k]));
        if (s.realTimeFactor > 0) {
            // Physics slower than real time: the tissue moves in slow motion; say so in red.
            const bool slow = s.realTimeFactor < 1;
            p.setPen(slow ? QColor(230, 80, 60) : QColor(140, 140, 140));
            p.drawText(px, h - 36,
                       slow ? QString::asprintf("Physics %.1f ms: %.2fx real time", s.physicsMs, s.realTimeFactor)
                            : QString::asprintf("Physics %.1f ms/frame: real time", s.physicsMs));
        }
        p.setPen(QColor(140, 140, 140));
        p.drawText(px, h - 16, QString::asprintf("frame %d", s.frame));
    }

    QImage render() {
        QImage img(size().isEmpty() ? QSize(960, 600) : size(), QImage::Format_RGB32);
        QPainter p(&img);
        paint(p, img.size());
        return img;
    }
    /// The session is over: the end-of-session screen replaces the view.
    void showVerdict(const Assessment& a) {
        m_verdict = a;
        update();
    }
    bool showsVerdict() const { return m_verdict.has_value(); }

protected:
    void paintEvent(QPaintEvent*) override {
        QPainter p(this);
        paint(p, size());
    }
    void keyPressEvent(QKeyEvent* e) override {
        if (!e->isAutoRepeat() &&
            (e->key() == Qt::Key_Escape || e->key() == Qt::Key_Return || e->key() == Qt::Key_Enter)) {
            if (m_verdict)
                close(); // leave the end screen
            else if (e->key() == Qt::Key_Escape)
                m_stop = true; // end the session: its verdict follows
            return;
        }
        key(e, true);
    }
    void keyReleaseEvent(QKeyEvent* e) override { key(e, false); }
    void mouseMoveEvent(QMouseEvent* e) override {
        const QPointF pos = e->position();
        if (m_keyboard && (e->buttons() & Qt::LeftButton))
            m_keyboard->addMouse(pos.x() - m_mouse.x(), pos.y() - m_mouse.y(), 0);
        m_mouse = pos;
    }
    void mousePressEvent(QMouseEvent* e) override { m_mouse = e->position(); }
    void wheelEvent(QWheelEvent* e) override {
        if (m_keyboard) m_keyboard->addMouse(0, 0, e->angleDelta().y() / 120.0);
    }
    bool event(QEvent* e) override {
        if (e->type() == QEvent::Close && !m_verdict && !m_stop) {
            // Closing a running session ends it; the window stays for its verdict.
            m_stop = true;
            e->ignore();
            return true;
        }
        if (e->type() == QEvent::Close) m_stop = true;
        return QRasterWindow::event(e);
    }

private:
    void paint(QPainter& p, const QSize& size) {
        if (m_verdict)
            paintVerdictScreen(p, size, *m_verdict, m_title);
        else
            paintHud(p, size);
    }
    void key(QKeyEvent* e, bool down) {
        if (e->isAutoRepeat()) return;
        if (e->key() == Qt::Key_S && down && m_viewport) { // the stereo switch, with any device
            m_viewport->cycleStereo();
            m_viewport->refresh();
            update();
            return;
        }
        if (!m_keyboard) return;
        if (const auto k = keyboardKey(e->key())) m_keyboard->setKey(*k, down);
    }
    LiveView& m_live;
    std::string m_title, m_instructions;
    std::vector<std::string> m_steps; ///< the task's ordered steps (scene "steps"), shown numbered
    KeyboardDevice* m_keyboard;
    std::atomic<bool>& m_stop;
    Viewport3D* m_viewport;
    QPointF m_mouse;
    std::optional<Assessment> m_verdict;
};

} // namespace

std::string windowModeUnavailable() {
    const char* platform = std::getenv("QT_QPA_PLATFORM");
    const char* display = std::getenv("DISPLAY");
    const char* wayland = std::getenv("WAYLAND_DISPLAY");
    if ((platform && *platform) || (display && *display) || (wayland && *wayland)) return "";
    return "window mode needs a display (DISPLAY or WAYLAND_DISPLAY), or QT_QPA_PLATFORM=offscreen; or use --headless";
}

namespace {

/// Writes `image` as PNG to `path` atomically; false (logged) when it cannot be written.
bool savePng(const QImage& image, const std::string& path) {
    QByteArray bytes;
    QBuffer buf(&bytes);
    buf.open(QIODevice::WriteOnly);
    image.save(&buf, "PNG");
    try {
        writeFileAtomic(path, std::string_view(bytes.constData(), static_cast<size_t>(bytes.size())));
        return true;
    } catch (const std::exception& e) {
        log::error(e.what());
        return false;
    }
}

} // namespace

SessionResult runWindow(LoadedCase& loaded, RunOptions options, const WindowShots& shots) {
    LiveView live;
    std::atomic<bool> stop{false};
    options.live = &live;
    options.stop = &stop;
    // The physics thread is made first, at normal priority, and starts when the window is up. The
    // window's thread then drops to SCHED_IDLE, and with it every thread it makes (Qt's, the
    // software rasterizer's): the picture runs on what the physics leaves of the CPUs and never
    // preempts the physics or its constraint workers (on 2 cores a render of tens of ms took the
    // core a worker needed, and the whole step waited for it). The servo thread has its own
    // real-time priority.
    SessionResult result;
    std::atomic<bool> resultReady{false};
    std::promise<void> windowUp;
    std::thread physics([&, up = windowUp.get_future()]() mutable {
        up.wait();
        if (!stop) result = runSession(loaded, options); // not when the window never came up
        resultReady = true;
    });
    struct PhysicsGuard { // on every way out: the session is stopped and joined
        std::promise<void>& up;
        std::thread& t;
        std::atomic<bool>& stop;
        bool started = false;
        void start() {
            started = true;
            up.set_value();
        }
        void end() { // stops the session and joins it (once; again on every way out)
            stop = true;
            if (!started) up.set_value();
            started = true;
            if (t.joinable()) t.join();
        }
        ~PhysicsGuard() { end(); }
    } guard{windowUp, physics, stop};
    const sched_param idle{};
    if (pthread_setschedparam(pthread_self(), SCHED_IDLE, &idle) != 0)
        log::warn("the window could not lower its priority (SCHED_IDLE); its renders share the CPUs with the physics");
    static int argc = 1;
    static char arg0[] = "viscera-player";
    static char* argv[] = {arg0, nullptr};
    QGuiApplication app(argc, argv);
    std::setlocale(LC_NUMERIC, "C"); // Qt took the user's locale: the summary's figures keep their point
    const std::string title = loaded.package->manifest().title.value_or(loaded.package->manifest().caseId);
    Viewport3D viewport(loaded, live, 640, 480);
    if (!viewport.available()) log::warn("3D view off (side view instead): " + viewport.whyNot());
    TraineeWindow window(live, title, loaded.scene.instructions, loaded.scene.steps,
                         dynamic_cast<KeyboardDevice*>(options.device), stop, &viewport);
    window.show();
    guard.start();
    std::vector<std::string> failed;
    bool shotTaken = false;
    QTimer timer;
    // The 3D view never takes time the physics needs (RenderPacer); the HUD repaints at every tick.
    QElapsedTimer sinceRender;
    RenderPacer pacer;
    QObject::connect(&timer, &QTimer::timeout, [&] {
        bool finished;
        LiveState state;
        {
            std::lock_guard<std::mutex> lock(live.mutex);
            finished = live.finished;
            state = live.state;
        }
        const double since = sinceRender.isValid() ? double(sinceRender.elapsed()) : -1.0;
        if (pacer.due(state, finished, since, viewport.lastFrameMs())) {
            sinceRender.start();
            viewport.refresh();
        }
        window.requestUpdate();
        window.update();
        if (!finished) return;
        if (!shotTaken && !shots.view.empty() && !savePng(window.render(), shots.view)) failed.push_back(shots.view);
        shotTaken = true;
        if (!resultReady) return; // the session's figures and verdict are being made
        timer.stop();
        window.showVerdict(result.assessment);
        if (!shots.endScreen.empty() && !savePng(window.render(), shots.endScreen)) failed.push_back(shots.endScreen);
        // A session of a given length (--frames) ends with it; the trainee's stays on its verdict
        // until closed (Enter, Esc or the window's close button).
        if (options.frames > 0) app.quit();
    });
    timer.start(33);
    app.exec();
    guard.end();
    const sched_param normal{};
    // Back for the summary and report (refused without CAP_SYS_NICE: they then run at idle priority).
    pthread_setschedparam(pthread_self(), SCHED_OTHER, &normal);
    for (const std::string& f : failed)
        result.errors.push_back("screenshot " + f + " could not be written");
    return result;
}

} // namespace viscera::player
