// Live preview under a continuous drag (issue: studio application): the liver project open in
// the studio's main window, a Valanis–Landel material on the organ, and a 5 s drag of one f′
// control point with a mouse event every 16 ms. Measures, in one run:
//   - frames from an edit to the preview showing it: for every edit, the preview frames that
//     completed after the edit before the frame that simulates it started (0: the next frame to
//     start shows it; 1: the frame in progress at the edit finished first);
//   - the UI thread's longest stall: the largest gap between two runs of a 1 ms timer (the event
//     loop runs as in a session: moves come from a 16 ms timer), the longest single mouse-event
//     handling (edit, check, undo command, plots), the viewport's frame time (on its render
//     thread with the default host), the slowest event deliveries on the UI thread (receiver,
//     event type, and how much of it was widget painting) and each widget's paint cost;
//   - the preview's physics cost per frame;
//   - the project texts written during the drag (studio::projectTextCount: 0 for typed edits).
// Writes <out>/studio_preview.json and screenshots of the main window (<out>/studio_main.png,
// the material dock, the viewport). Run under a display (Xvfb):
//   xvfb-run -a -s "-screen 0 1920x1200x24" ./build/bench/bench_studio_preview [out-dir] [seconds] [scene|paused]
//   [width height] [window|widget]     (the viewport's host; default window)
#include "app/curve_editor.hpp"
#include "app/fit_dialog.hpp"
#include "app/main_window.hpp"
#include "app/material_panel.hpp"
#include "app/plot_widget.hpp"
#include "app/studio_app.hpp"
#include "app/viewport.hpp"
#include "studio_bench_support.hpp"

#include <QApplication>
#include <QDockWidget>
#include <QElapsedTimer>
#include <QEventLoop>
#include <QLabel>
#include <QLineEdit>
#include <QMouseEvent>
#include <QScreen>
#include <QTimer>

#include "sim/material/laws.hpp"
#include "sim/material/material_response.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <numeric>

namespace {

using namespace viscera;

using bench::send;
using bench::waitFor;

double percentile(std::vector<double> v, double q) {
    if (v.empty()) return 0;
    std::sort(v.begin(), v.end());
    return v[std::min(v.size() - 1, static_cast<size_t>(q * (v.size() - 1) + 0.5))];
}

/// Times every top-level event delivery on the UI thread, to name what the longest stalls are
/// made of (receiver class and event type).
class TimingApplication : public QApplication {
public:
    using QApplication::QApplication;
    struct Delivery {
        double ms;
        std::string what;
        double paintMs; ///< of which widget paint events
    };
    bool recording = false;
    std::vector<Delivery> slowest; ///< the 8 slowest while recording
    struct PaintCost {
        double max = 0, total = 0;
        int count = 0;
    };
    std::map<std::string, PaintCost> paintMs; ///< paint events per widget

    bool notify(QObject* receiver, QEvent* e) override {
        if (recording && m_depth > 0 && e->type() == QEvent::Paint) {
            QElapsedTimer t;
            t.start();
            ++m_depth;
            const bool r = QApplication::notify(receiver, e);
            --m_depth;
            auto& v =
                paintMs[std::string(receiver->metaObject()->className()) + "/" + receiver->objectName().toStdString()];
            const double ms = t.nsecsElapsed() * 1e-6;
            v.max = std::max(v.max, ms);
            v.total += ms;
            ++v.count;
            if (m_depth == 1) m_nestedPaintMs += ms;
            return r;
        }
        if (m_depth > 0 || !recording) {
            ++m_depth;
            const bool r = QApplication::notify(receiver, e);
            --m_depth;
            return r;
        }
        const std::string what = std::string(receiver->metaObject()->className()) + "/" +
                                 receiver->objectName().toStdString() + " event " + std::to_string(e->type());
        QElapsedTimer t;
        t.start();
        m_nestedPaintMs = 0;
        ++m_depth;
        const bool r = QApplication::notify(receiver, e);
        --m_depth;
        const double ms = t.nsecsElapsed() * 1e-6;
        if (slowest.size() < 8 || ms > slowest.back().ms) {
            slowest.push_back({ms, what, m_nestedPaintMs});
            std::sort(slowest.begin(), slowest.end(), [](auto& a, auto& b) { return a.ms > b.ms; });
            if (slowest.size() > 8) slowest.pop_back();
        }
        return r;
    }

private:
    int m_depth = 0;
    double m_nestedPaintMs = 0;
};

} // namespace

int main(int argc, char** argv) {
    const std::filesystem::path out = argc > 1 ? argv[1] : "bench-out/studio";
    const double seconds = argc > 2 ? std::atof(argv[2]) : 5.0;
    // "paused": the same drag with the preview paused, to separate the UI's own cost from the
    // simulation sharing the machine's cores
    const bool paused = argc > 3 && std::string(argv[3]) == "paused";
    std::filesystem::create_directories(out);
    studio::setStudioSurfaceFormat();
    TimingApplication app(argc, argv);
    QCoreApplication::setOrganizationName("VisceraBench");
    QCoreApplication::setApplicationName("StudioPreview");
    const auto host = studio::viewportHostFromText(argc > 6 ? argv[6] : "window");
    if (!host) {
        std::fprintf(stderr, "viewport host: '%s' is not window or widget\n", argv[6]);
        return 2;
    }
    studio::MainWindow w;
    w.setViewportHost(*host);
    w.setConfirmDiscard(false);
    w.resize(argc > 4 ? std::atoi(argv[4]) : 1600, argc > 5 ? std::atoi(argv[5]) : 1000);
    w.show();
    const std::string project = std::string(VISCERA_SOURCE_DIR) + "/projects/liver";
    if (!w.openProject(QString::fromStdString(project))) return 1;
    w.selectBody(0);
    if (auto why = w.materialPanel()->applyPreset("neo_hookean", 8000, 0.45); !why.isEmpty()) {
        std::fprintf(stderr, "preset: %s\n", why.toUtf8().constData());
        return 1;
    }
    w.preview()->setAccuracyEvery(30);
    QObject::connect(w.preview(), &studio::Preview::logMessage,
                     [](const QString& m) { std::fprintf(stderr, "%s\n", m.toUtf8().constData()); });
    std::vector<double> viewportPaintMs, viewportScale;
    QTimer paintProbe;
    QObject::connect(&paintProbe, &QTimer::timeout, [&] {
        viewportPaintMs.push_back(w.viewport()->lastPaintMs());
        viewportScale.push_back(w.viewport()->renderScale());
    });
    std::printf("waiting for the preview (meshing the liver)...\n");
    if (!waitFor([&] { return w.viewport()->meshCount() > 0 && w.preview()->snapshot().frames > 40; }, 300000)) {
        std::fprintf(stderr, "the preview did not start: %s\n", w.verdictLabel()->text().toUtf8().constData());
        return 1;
    }
    waitFor([&] { return !w.errorPlot()->series().empty(); }, 60000);

    // the drag: the first movable point of f′ moves up and down by ±30 % of its neighbours' gap
    studio::CurveEditor* e = w.materialPanel()->editor(0);
    const auto& pts = e->points();
    size_t i = 1;
    while (i + 1 < pts.size() && (pts[i].x == 1.0 || pts[i - 1].x == 1.0 || pts[i + 1].x == 1.0))
        ++i;
    const QPointF start = e->toWidget({pts[i].x, pts[i].y});
    const double lo = pts[i - 1].y, hi = pts[i + 1].y, y0 = pts[i].y;

    std::vector<double> timerGaps, handlerMs, latencyFrames;
    QElapsedTimer clock;
    clock.start();
    qint64 lastTick = clock.nsecsElapsed();
    QTimer probe;
    probe.setTimerType(Qt::PreciseTimer);
    probe.setInterval(1);
    QObject::connect(&probe, &QTimer::timeout, [&] {
        const qint64 now = clock.nsecsElapsed();
        timerGaps.push_back((now - lastTick) * 1e-6);
        lastTick = now;
    });
    struct PendingEdit {
        uint64_t serial, framesAtEdit;
    };
    std::vector<PendingEdit> pending;
    const auto s0 = w.preview()->snapshot();
    const uint64_t frames0 = s0.frames;
    const uint64_t texts0 = studio::projectTextCount(); // project serializations (none for a typed edit)
    w.preview()->setPaused(paused);
    probe.start();
    app.recording = true;
    paintProbe.start(50);
    // Event-driven, like a user's session: a mouse move every 16 ms from a timer, the event loop
    // sleeping in between (no polling loop of the bench's own on the UI thread).
    send(e, QEvent::MouseButtonPress, start, Qt::LeftButton, Qt::LeftButton);
    int events = 0;
    const qint64 dragStart = clock.elapsed();
    uint64_t seenRevision = 0;
    auto resolve = [&] {
        // edits the preview has now taken: frames completed after the edit before the frame
        // that shows it started
        if (w.preview()->revision() == seenRevision) return;
        seenRevision = w.preview()->revision();
        const auto s = w.preview()->snapshot();
        pending.erase(std::remove_if(pending.begin(), pending.end(),
                                     [&](const PendingEdit& p) {
                                         if (s.serial < p.serial) return false;
                                         latencyFrames.push_back(static_cast<double>(s.appliedAfter - p.framesAtEdit));
                                         return true;
                                     }),
                      pending.end());
    };
    QTimer mover;
    mover.setTimerType(Qt::PreciseTimer);
    QObject::connect(&mover, &QTimer::timeout, [&] {
        const qint64 now = clock.elapsed();
        const double phase = (now - dragStart) / 1000.0 * 2.0; // one cycle per 0.5 s
        const double y = y0 + 0.3 * std::sin(phase * 3.14159265) * std::min(hi - y0, y0 - lo);
        const QPointF p(start.x(), e->toWidget({pts[i].x, y}).y());
        QElapsedTimer h;
        h.start();
        send(e, QEvent::MouseMove, p, Qt::NoButton, Qt::LeftButton);
        handlerMs.push_back(h.nsecsElapsed() * 1e-6);
        ++events;
        const auto [serial, framesAtSubmit] = w.lastPreviewSubmit();
        pending.push_back({serial, framesAtSubmit});
        resolve();
    });
    mover.start(16);
    QEventLoop loop;
    QTimer::singleShot(static_cast<int>(seconds * 1000), &loop, &QEventLoop::quit);
    loop.exec();
    mover.stop();
    app.recording = false;
    resolve();
    send(e, QEvent::MouseButtonRelease, e->toWidget({pts[i].x, pts[i].y}), Qt::LeftButton, Qt::NoButton);
    probe.stop();
    const auto s1 = w.preview()->snapshot();
    w.preview()->setPaused(false);
    // after the drag, the error sampler takes the new state (once no edit came for 0.5 s)
    const int sampledBefore = s1.accuracy ? s1.accuracy->frame : -1;
    waitFor(
        [&] {
            const auto s = w.preview()->snapshot();
            return s.accuracy && s.accuracy->frame > sampledBefore &&
                   static_cast<uint64_t>(s.accuracy->frame) > s1.frames;
        },
        60000);
    waitFor([&] { return false; }, 300); // let the last frames and plots land
    w.pollPreview();

    // screenshots of what the user sees
    // from the screen, as the user sees it: the viewport is a native window of its own, which a
    // widget grab (QWidget::grab) does not contain
    w.screen()->grabWindow(w.winId()).save(QString::fromStdString((out / "studio_main.png").string()));
    if (auto* d = w.findChild<QDockWidget*>("materialDock"))
        d->grab().save(QString::fromStdString((out / "studio_material.png").string()));
    if (auto* d = w.findChild<QDockWidget*>("plotsDock"))
        d->grab().save(QString::fromStdString((out / "studio_plots.png").string()));
    w.viewport()->grabFramebuffer().save(QString::fromStdString((out / "studio_viewport.png").string()));
    {
        // the fit dialog on synthetic Neo-Hookean data (mu 1 kPa, lambda 10 kPa, stretch 0.7-1.5)
        auto nh = sim::makeEnergyDensity("neo_hookean", 1000.0, 10000.0);
        const auto csv = out / "nh_uniaxial.csv";
        {
            std::ofstream f(csv);
            f.precision(17);
            f << "stretch,nominal stress (Pa)\n";
            for (int k = 0; k < 41; ++k) {
                const double l = 0.7 + 0.8 * k / 40.0;
                f << l << "," << sim::uniaxialNominalStress(*nh, l).nominalStress << "\n";
            }
        }
        studio::FitDialog dlg(w.document(), 0, &w);
        dlg.resize(760, 560);
        dlg.show();
        dlg.fileField()->setText(QString::fromStdString(csv.string()));
        dlg.runFit();
        waitFor([&] { return false; }, 200);
        dlg.grab().save(QString::fromStdString((out / "studio_fit.png").string()));
    }

    const double maxGap = timerGaps.empty() ? 0 : *std::max_element(timerGaps.begin(), timerGaps.end());
    const double maxHandler = handlerMs.empty() ? 0 : *std::max_element(handlerMs.begin(), handlerMs.end());
    const double maxLatency =
        latencyFrames.empty() ? -1 : *std::max_element(latencyFrames.begin(), latencyFrames.end());
    std::vector<double> physics(s1.frameMs.begin(), s1.frameMs.end());
    nlohmann::json j;
    j["project"] = "liver (organ: Valanis-Landel, Neo-Hookean preset E 8000 Pa, nu 0.45)";
    j["drag_seconds"] = seconds;
    j["preview_paused"] = paused;
    j["drag_events"] = events;
    j["project_texts_during_drag"] = studio::projectTextCount() - texts0;
    j["preview_frames_during_drag"] = s1.frames - frames0;
    j["edits_resolved"] = latencyFrames.size();
    j["edit_to_preview_frames"] = {
        {"max", maxLatency},
        {"mean", latencyFrames.empty()
                     ? -1
                     : std::accumulate(latencyFrames.begin(), latencyFrames.end(), 0.0) / latencyFrames.size()}};
    j["ui_timer_gap_ms"] = {{"max", maxGap}, {"p99", percentile(timerGaps, 0.99)}, {"p50", percentile(timerGaps, 0.5)}};
    auto top = [](std::vector<double> v) {
        std::sort(v.rbegin(), v.rend());
        v.resize(std::min<size_t>(v.size(), 5));
        return v;
    };
    j["ui_timer_gap_ms"]["largest"] = top(timerGaps);
    for (const auto& d : app.slowest)
        j["slowest_event_deliveries"].push_back({{"ms", d.ms}, {"what", d.what}, {"widget_paint_ms", d.paintMs}});
    for (const auto& [what, c] : app.paintMs)
        if (c.max > 0.5) j["widget_paint_ms"][what] = {{"max", c.max}, {"mean", c.total / c.count}, {"count", c.count}};
    j["mouse_event_ms"] = {
        {"max", maxHandler},
        {"p99", percentile(handlerMs, 0.99)},
        {"mean", handlerMs.empty() ? 0 : std::accumulate(handlerMs.begin(), handlerMs.end(), 0.0) / handlerMs.size()}};
    j["physics_ms_per_frame"] = {
        {"mean", physics.empty() ? 0 : std::accumulate(physics.begin(), physics.end(), 0.0) / physics.size()},
        {"p99", percentile(physics, 0.99)}};
    j["viewport_paint_ms"] = {
        {"max", viewportPaintMs.empty() ? 0 : *std::max_element(viewportPaintMs.begin(), viewportPaintMs.end())},
        {"p50", percentile(viewportPaintMs, 0.5)}};
    j["viewport_render_scale"] = {
        {"min", viewportScale.empty() ? 1 : *std::min_element(viewportScale.begin(), viewportScale.end())},
        {"last", viewportScale.empty() ? 1 : viewportScale.back()}};
    if (const auto s2 = w.preview()->snapshot(); s2.accuracy) {
        j["error_sample"] = {{"frame", s2.accuracy->frame},
                             {"of", s2.accuracyOf.toStdString()},
                             {"xpbd_iterations", s2.accuracy->iterations},
                             {"xpbd_rel_error", s2.accuracy->relError},
                             {"xpbd_time_ms", s2.accuracy->timeMs}};
        if (s2.accuracyNewton)
            j["error_sample"]["newton"] = {{"rel_error", s2.accuracyNewton->relError},
                                           {"time_ms", s2.accuracyNewton->timeMs}};
    }
    j["verdict"] = w.verdictLabel()->text().toStdString();
    j["renderer"] = w.viewport()->rendererInfo().toStdString();
    j["viewport_host"] = studio::viewportHostText(*host).toStdString();
    std::ofstream(out / "studio_preview.json") << j.dump(2) << "\n";
    std::printf("%s\n", j.dump(2).c_str());
    w.preview()->stop();
    return 0;
}
