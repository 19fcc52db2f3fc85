// Light-sample painting in the studio (issue: studio painting): a project open in the main window
// (default: the liver sample, whose organ carries a painted map), one body selected, the Light
// samples tool on, and one more 1× stroke dragged across the body at the centre of the viewport.
// Measures the cost of a dab on the UI thread (mouse move), the commit (the area-keeping replay
// of every operation), and writes the window from the screen (legend in the dock), the viewport
// and the side-by-side comparison of uniform 1× and the painted map. Run under a display (Xvfb):
//   xvfb-run -a -s "-screen 0 1920x1200x24" ./build/bench/bench_studio_samples [out-dir] [project] [body] [radius-mm]
#include "app/main_window.hpp"
#include "app/sample_compare.hpp"
#include "app/sample_painter.hpp"
#include "app/studio_app.hpp"
#include "app/viewport.hpp"
#include "studio_bench_support.hpp"

#include <QAction>
#include <QApplication>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QElapsedTimer>
#include <QLabel>
#include <QScreen>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>

using namespace viscera;
using bench::send;
using bench::waitFor;

int main(int argc, char** argv) {
    const std::filesystem::path out = argc > 1 ? argv[1] : "bench-out/studio-samples";
    const std::string projectName = argc > 2 ? argv[2] : "liver";
    const std::string bodyName = argc > 3 ? argv[3] : "organ";
    const double radiusMm = argc > 4 ? std::atof(argv[4]) : 8.0;
    std::filesystem::create_directories(out);
    studio::setStudioSurfaceFormat();
    QApplication app(argc, argv);
    QCoreApplication::setOrganizationName("VisceraBench");
    QCoreApplication::setApplicationName("StudioSamples");
    studio::MainWindow w;
    const int body = bench::openSampleBody(w, projectName, bodyName);
    if (body < 0) return 1;
    QElapsedTimer prep;
    prep.start();
    w.findChild<QAction*>("actionPaintSamples")->trigger();
    studio::SamplePainter* painter = w.samplePainter();
    if (!waitFor([&] { return painter->ready(); }, 60000)) {
        std::fprintf(stderr, "painter: %s\n", painter->status().toUtf8().constData());
        return 1;
    }
    const double prepareMs = prep.elapsed();
    w.findChild<QComboBox*>("sampleClass")->setCurrentIndex(2); // 1×
    w.findChild<QDoubleSpinBox*>("sampleRadius")->setValue(radiusMm);
    studio::Viewport* v = w.viewport();
    v->frameAll();
    waitFor([] { return false; }, 300);
    const QPoint c(v->width() / 2, v->height() / 2 + v->height() / 8);
    std::vector<double> dabMs;
    send(v, QEvent::MouseButtonPress, c - QPoint(60, 0), Qt::LeftButton, Qt::LeftButton);
    for (int k = 1; k <= 30; ++k) {
        QElapsedTimer t;
        t.start();
        send(v, QEvent::MouseMove, c - QPoint(60, 0) + QPoint(4 * k, 0), Qt::NoButton, Qt::LeftButton);
        dabMs.push_back(t.nsecsElapsed() * 1e-6);
    }
    QElapsedTimer commit;
    commit.start();
    send(v, QEvent::MouseButtonRelease, c + QPoint(60, 0), Qt::LeftButton, Qt::NoButton);
    const double commitMs = commit.nsecsElapsed() * 1e-6;
    waitFor([] { return false; }, 1500);
    w.screen()->grabWindow(w.winId()).save(QString::fromStdString((out / "samples_main.png").string()));
    v->grabFramebuffer().save(QString::fromStdString((out / "samples_viewport.png").string()));
    QElapsedTimer cmpTime;
    cmpTime.start();
    studio::SampleCompareDialog* cmp = w.openSampleCompare();
    if (!cmp) return 1;
    cmp->resize(1100, 560);
    cmp->waitForFinished();
    const double compareMs = cmpTime.elapsed();
    waitFor([] { return false; }, 500);
    cmp->grab().save(QString::fromStdString((out / "samples_compare.png").string()));

    const auto a = painter->areas();
    const double all = a[0] + a[1] + a[2] + a[3];
    std::sort(dabMs.begin(), dabMs.end());
    nlohmann::json j;
    j["project"] = projectName;
    j["body"] = bodyName;
    j["surface_vertices"] = painter->surface().vertexCount();
    j["prepare_ms"] = prepareMs;
    j["move_event_ms"] = {{"p50", dabMs[dabMs.size() / 2]}, {"max", dabMs.back()}};
    j["commit_ms"] = commitMs;
    j["operations"] = w.document()->project().bodies[body].lightSamples.size();
    j["area_share"] = {{"unpainted", a[0] / all}, {"1x", a[1] / all}, {"4x", a[2] / all}, {"8x", a[3] / all}};
    j["legend"] = w.findChild<QLabel*>("sampleLegend")->text().toStdString();
    j["compare_ms"] = compareMs;
    if (cmp->result()) {
        const render::SamplingComparison& r = *cmp->result();
        j["compare"] = {{"rmse_near_uniform1", r.rmseNearUniform},
                        {"rmse_near_painted", r.rmseNearPainted},
                        {"frame_ms_uniform1", r.msUniform},
                        {"frame_ms_painted", r.msPainted}};
    } else {
        j["compare_error"] = cmp->error().toStdString();
    }
    std::ofstream(out / "studio_samples.json") << j.dump(2) << "\n";
    std::printf("%s\n", j.dump(2).c_str());
    w.preview()->stop();
    return 0;
}
