// Stiffness painting in the studio (issue: studio painting): a project open in the main window,
// one body selected, the Paint stiffness tool on, and a stroke dragged across the body at the
// centre of the viewport. Measures the skeleton preparation, the cost of one dab on the UI
// thread (weights + overlay), and the painted weights; writes the window from the screen and
// the viewport. Run under a display (Xvfb):
//   xvfb-run -a -s "-screen 0 1920x1200x24" ./build/bench/bench_studio_paint [out-dir] [project] [body] [radius-mm]
//   [cut view|x|y|z]     (then also the cut-away view at the middle, facing the camera or
//                         across an axis: paint_cut.png)
#include "app/main_window.hpp"
#include "app/stiffness_painter.hpp"
#include "app/studio_app.hpp"
#include "app/viewport.hpp"
#include "studio_bench_support.hpp"

#include <QAction>
#include <QApplication>
#include <QCheckBox>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QElapsedTimer>
#include <QEventLoop>
#include <QMouseEvent>
#include <QScreen>
#include <QTimer>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>

namespace {

using namespace viscera;

using bench::send;
using bench::waitFor;

} // namespace

int main(int argc, char** argv) {
    const std::filesystem::path out = argc > 1 ? argv[1] : "bench-out/studio-paint";
    const std::string projectName = argc > 2 ? argv[2] : "rectum";
    const std::string bodyName = argc > 3 ? argv[3] : "fat";
    const double radiusMm = argc > 4 ? std::atof(argv[4]) : 15.0;
    std::filesystem::create_directories(out);
    studio::setStudioSurfaceFormat();
    QApplication app(argc, argv);
    QCoreApplication::setOrganizationName("VisceraBench");
    QCoreApplication::setApplicationName("StudioPaint");
    studio::MainWindow w;
    const int body = bench::openSampleBody(w, projectName, bodyName);
    if (body < 0) return 1;
    QElapsedTimer prep;
    prep.start();
    w.findChild<QAction*>("actionPaintStiffness")->trigger();
    studio::StiffnessPainter* painter = w.painter();
    if (!waitFor([&] { return painter->ready(); }, 600000)) {
        std::fprintf(stderr, "painter: %s\n", painter->status().toUtf8().constData());
        return 1;
    }
    const double prepareMs = prep.elapsed();
    w.findChild<QDoubleSpinBox*>("paintRadius")->setValue(radiusMm);
    w.findChild<QDoubleSpinBox*>("paintStrength")->setValue(3.0);
    studio::Viewport* v = w.viewport();
    v->frameAll();
    waitFor([] { return false; }, 300);
    // the stroke: across the centre, through the viewport's own handlers
    const QPoint c(v->width() / 2, v->height() / 2);
    std::vector<double> dabMs;
    send(v, QEvent::MouseButtonPress, c - QPoint(80, 0), Qt::LeftButton, Qt::LeftButton);
    for (int k = 1; k <= 40; ++k) {
        QElapsedTimer t;
        t.start();
        send(v, QEvent::MouseMove, c - QPoint(80, 0) + QPoint(4 * k, 0), Qt::NoButton, Qt::LeftButton);
        dabMs.push_back(t.nsecsElapsed() * 1e-6);
    }
    const size_t dabs = painter->pendingDabs().size();
    QElapsedTimer commit;
    commit.start();
    send(v, QEvent::MouseButtonRelease, c + QPoint(80, 0), Qt::LeftButton, Qt::NoButton);
    const double commitMs = commit.nsecsElapsed() * 1e-6;
    waitFor([] { return false; }, 1500);
    w.screen()->grabWindow(w.winId()).save(QString::fromStdString((out / "paint_main.png").string()));
    v->grabFramebuffer().save(QString::fromStdString((out / "paint_viewport.png").string()));
    const std::string axis = argc > 5 ? argv[5] : "";
    if (axis == "view" || axis == "x" || axis == "y" || axis == "z") {
        w.findChild<QComboBox*>("paintCutAxis")->setCurrentIndex(axis == "view" ? 0 : 1 + (axis[0] - 'x'));
        w.findChild<QCheckBox*>("paintCut")->setChecked(true);
        waitFor([] { return false; }, 800);
        w.screen()->grabWindow(w.winId()).save(QString::fromStdString((out / "paint_cut_main.png").string()));
        v->grabFramebuffer().save(QString::fromStdString((out / "paint_cut.png").string()));
    }

    const auto& wts = painter->weights();
    const double base = painter->params().baseWeight;
    const size_t painted = std::count_if(wts.begin(), wts.end(), [&](double x) { return x != base; });
    std::sort(dabMs.begin(), dabMs.end());
    nlohmann::json j;
    j["project"] = projectName;
    j["body"] = bodyName;
    j["nodes"] = wts.size();
    j["skeleton_nodes"] = painter->skeleton().nodes.size();
    j["prepare_ms"] = prepareMs;
    j["radius_mm"] = radiusMm;
    j["dabs"] = dabs;
    j["move_event_ms"] = {{"p50", dabMs[dabMs.size() / 2]}, {"max", dabMs.back()}};
    j["commit_ms"] = commitMs;
    j["painted_nodes"] = painted;
    j["weight_max"] = *std::max_element(wts.begin(), wts.end());
    j["strokes_in_project"] = w.document()->project().bodies[body].paint->strokes.size();
    j["status"] = painter->status().toStdString();
    std::ofstream(out / "studio_paint.json") << j.dump(2) << "\n";
    std::printf("%s\n", j.dump(2).c_str());
    w.preview()->stop();
    return 0;
}
