// A new procedure built in the studio by GUI actions only [issue 57 item 4]: a laparoscopic
// cholecystectomy step (lift the fundus, open the peritoneum over the cystic duct, clip the duct
// and the artery twice each, cut each between its clips) from the hepatocystic anatomy made by
// code as bought anatomy (`viscera-studio sample hepatocystic`): New project, Import anatomy (the
// gallbladder, both ducts and the artery with their texture), Make simulation-ready,
// Tetrahedralize, the tissue held where it is attached, the clip sites and the cut lines picked
// on the duct and the artery, a peritoneum layer over Calot's triangle, the liver imported as a
// surrounding, an abdominal wall, four instruments on their masters with their ports clicked on
// the wall, the laparoscope from the studio camera, the task and the limits typed, the case
// exported signed. No project JSON is written by hand or by the test. The exported case verifies
// and runs in the player: a device recording that opens the peritoneum with the hook, clips
// twice and cuts between passes its assessment; the same recording without the clips fails on
// clips_on_target. Screenshots through the laparoscope at the start, after the peritoneum is
// opened, after the clips and after the cut (VISCERA_GUI_SHOTS).
#include "app/anatomy_steps.hpp"
#include "app/assessment_panel.hpp"
#include "app/document.hpp"
#include "app/export_runner.hpp"
#include "app/hold_tool.hpp"
#include "app/import_placement.hpp"
#include "app/instrument_panel.hpp"
#include "app/port_tool.hpp"
#include "app/project_tree_panel.hpp"
#include "app/rehearsal.hpp"
#include "app/rehearse_panel.hpp"
#include "app/scope_task_panel.hpp"
#include "app/studio_task.hpp"
#include "app/surroundings_panel.hpp"
#include "app/target_panel.hpp"
#include "app/target_tool.hpp"
#include "project/publishing.hpp"
#include "render/camera.hpp"
#include "sim/scene/instrument_track.hpp"
#include "window_fixture.hpp"

#include <QAction>
#include <QApplication>
#include <QCheckBox>
#include <QComboBox>
#include <QDialog>
#include <QDialogButtonBox>
#include <QDockWidget>
#include <QDoubleSpinBox>
#include <QElapsedTimer>
#include <QFileDialog>
#include <QInputDialog>
#include <QLabel>
#include <QLineEdit>
#include <QListView>
#include <QListWidget>
#include <QPlainTextEdit>
#include <QProcess>
#include <QPushButton>
#include <QRegularExpression>
#include <QSettings>
#include <QSignalSpy>
#include <QSpinBox>
#include <QTableWidget>
#include <QToolButton>
#include <QTreeWidgetItemIterator>
#include <QUndoStack>
#include <QWheelEvent>

#include <Eigen/Geometry>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <tuple>

using namespace viscera;
namespace fs = std::filesystem;
using ::testing::HasSubstr;

namespace {

// The hepatocystic sample's geometry (bake::hepatocysticAnatomy, metres): the cystic duct's axis
// from the gallbladder's neck to the common bile duct, points on the parts to hold and the task's
// sites on the duct's free stretch.
const sim::Vec3 kDuctFrom(0, -0.043, 0.009), kDuctTo(0.012, -0.075, 0.001);
const sim::Vec3 kDuctAxis = (kDuctTo - kDuctFrom).normalized();
sim::Vec3 onDuct(double t) {
    return kDuctFrom + t * (kDuctTo - kDuctFrom);
}
const sim::Vec3 kClipNear = onDuct(0.3), kClipFar = onDuct(0.56), kCut = onDuct(0.43);
// The cystic artery's axis (1.5 mm radius) from its proximal end by the common bile duct to the
// gallbladder's neck (it enters the neck at about 0.68); its clip sites and cut on the free stretch.
const sim::Vec3 kArteryFrom(0.024, -0.07, 0.008), kArteryTo(0.008, -0.036, 0.012);
const sim::Vec3 kArteryAxis = (kArteryTo - kArteryFrom).normalized();
sim::Vec3 onArtery(double t) {
    return kArteryFrom + t * (kArteryTo - kArteryFrom);
}
const sim::Vec3 kArteryClipNear = onArtery(0.28), kArteryClipFar = onArtery(0.52), kArteryCut = onArtery(0.4);
const sim::Vec3 kGallTop(0, -0.032, 0.024), kGallTopFundus(0, 0.02, 0.027);
const sim::Vec3 kFundus(0, 0.035, 0.006);
const sim::Vec3 kBileDuctNear(0.0121, -0.075, 0.0056), kBileDuctFar(0.0197, -0.122, -0.0036);
// The peritoneum over Calot's triangle (the studio's tissue layer region, m): the cystic duct, the
// artery's free stretch and the gallbladder's neck.
const char* const kPeritoneumMin = "-0.01 -0.078 -0.008";
const char* const kPeritoneumMax = "0.032 -0.038 0.02";
// The console's pedals column (haptics::Pedal bits): the deadman held, and with it the energy's
// cut pedal.
constexpr int kPedalsIdle = 4, kPedalsCut = 4 | 8;

struct CholeFixture : test::MainWindowFixture {
    CholeFixture() : MainWindowFixture("viscera-chole-gui") {}
    int actions = 0;                                     ///< GUI actions taken (clicks, drags, typed fields, keys)
    std::vector<std::pair<std::string, double>> timings; ///< long steps, seconds

    studio::AnatomySteps* steps() { return w->anatomySteps(); }
    const studio::Project& model() { return w->document()->project(); }

    /// The fixture's file dialog typer, counted as two actions (the path, Enter).
    void typeIntoFileDialog(const QString& path, const std::function<void()>& trigger) {
        MainWindowFixture::typeIntoFileDialog(path, trigger);
        actions += 2;
    }
    /// Types `text` into the line edit and presses Enter, as a user does.
    void typeField(QLineEdit* e, const QString& text) {
        ASSERT_NE(e, nullptr);
        e->setFocus();
        e->selectAll();
        QTest::keyClicks(e, text);
        QTest::keyClick(e, Qt::Key_Return);
        QCoreApplication::processEvents();
        actions += 2;
    }
    template <class W> W* find(const char* name) {
        W* x = nullptr;
        EXPECT_TRUE(test::waitFor([&] { return (x = w->findChild<W*>(name)) != nullptr; }, 10000)) << name;
        return x;
    }
    void clickButton(QAbstractButton* b) {
        ASSERT_NE(b, nullptr);
        if (qobject_cast<QCheckBox*>(b)) // on its box: a wide check box's label ends short of its middle
            QTest::mouseClick(b, Qt::LeftButton, Qt::NoModifier, QPoint(8, b->height() / 2));
        else
            QTest::mouseClick(b, Qt::LeftButton);
        ++actions;
    }
    void raise(const char* dock) {
        auto* d = w->findChild<QDockWidget*>(dock);
        ASSERT_NE(d, nullptr) << dock;
        d->raise(); // a click on its tab
        ++actions;
        QCoreApplication::processEvents();
    }
    /// The viewport position whose surface point (at rest) of mesh `name` lies nearest `p`:
    /// a coarse grid, then the pixels around the best; `gap`: that distance (m).
    QPoint nearest(const sim::Vec3& p, const QString& name, double* gap = nullptr) const {
        const studio::Viewport* v = w->viewport();
        QPoint best(-1, -1);
        double bestD = 1e30;
        auto consider = [&](QPoint at) {
            const auto hit = v->hitAt(at);
            if (!hit || hit->name != name) return;
            const double d = (hit->rest.cast<double>() - p).norm();
            if (d < bestD) bestD = d, best = at;
        };
        for (int y = 4; y < v->height(); y += 8)
            for (int x = 4; x < v->width(); x += 8)
                consider({x, y});
        const QPoint c = best;
        if (c.x() >= 0)
            for (int y = c.y() - 8; y <= c.y() + 8; ++y)
                for (int x = c.x() - 8; x <= c.x() + 8; ++x)
                    consider({x, y});
        if (gap) *gap = bestD;
        return best;
    }
    /// Types `text` into cell (row, col) of a table: F2, the text, Enter.
    void typeCell(QTableWidget* t, int row, int col, const QString& text) {
        ASSERT_GE(row, 0);
        t->setFocus();
        t->setCurrentCell(row, col);
        QTest::keyClick(t, Qt::Key_F2);
        QLineEdit* editor = nullptr; // the cell's editor (an earlier one may await deletion)
        for (QLineEdit* e : t->viewport()->findChildren<QLineEdit*>())
            if (e->isVisible()) editor = e;
        ASSERT_NE(editor, nullptr);
        editor->selectAll();
        QTest::keyClicks(editor, text);
        QTest::keyClick(editor, Qt::Key_Return);
        QCoreApplication::sendPostedEvents(nullptr, QEvent::DeferredDelete);
        QCoreApplication::processEvents();
        actions += 3;
    }
    static int rowOf(QTableWidget* t, const QString& text, int col = 0) {
        for (int r = 0; r < t->rowCount(); ++r)
            if (t->item(r, col) && t->item(r, col)->text() == text) return r;
        return -1;
    }
    void shot(const char* name) {
        test::saveShot(name);
        if (const char* dir = std::getenv("VISCERA_GUI_SHOTS"); dir && *dir)
            w->viewport()->grabFramebuffer().save(QString(dir) + "/" + name + "_viewport.png");
    }
    /// Clicks the toolbar's button of `a`, as a user does.
    void clickAction(QAction* a) {
        QToolButton* b = nullptr;
        for (QToolButton* t : w->findChildren<QToolButton*>())
            if (t->defaultAction() == a && t->isVisible()) b = t;
        ASSERT_NE(b, nullptr) << a->objectName().toStdString();
        clickButton(b);
    }
    /// A viewport position on the abdominal wall where a port of `port`'s limits, its shaft at
    /// rest towards `rest`, reaches every point of `targets` (5° and 5 mm inside its limits),
    /// the nearest such to `prefer`; (-1, -1): none.
    QPoint portPoint(const sim::PortDesc& port, const sim::Vec3& rest, const std::vector<sim::Vec3>& targets,
                     QPoint prefer) const {
        const studio::Viewport* v = w->viewport();
        QPoint best(-1, -1);
        double bestScore = -1e30;
        for (int y = 6; y < v->height(); y += 12)
            for (int x = 6; x < v->width(); x += 12) {
                const auto hit = v->hitAt({x, y});
                if (!hit || hit->name != "abdominal_wall") continue;
                const sim::Vec3 p = hit->world.cast<double>();
                const sim::Vec3 axis = rest - p;
                bool ok = axis.norm() > port.insertionMin + 0.005 && axis.norm() < port.insertionMax - 0.005;
                for (const sim::Vec3& t : targets) {
                    const sim::Vec3 d = t - p;
                    const double angle = std::acos(std::clamp(d.normalized().dot(axis.normalized()), -1.0, 1.0));
                    ok = ok && angle * 180 / M_PI < port.maxAngleDeg - 5 && d.norm() > port.insertionMin + 0.005 &&
                         d.norm() < port.insertionMax - 0.005;
                }
                const double score = -std::hypot(x - prefer.x(), y - prefer.y());
                if (ok && score > bestScore) bestScore = score, best = QPoint(x, y);
            }
        return best;
    }
    /// Where the viewport's camera shows the point `p` (behind the wall: its pixel all the same).
    QPoint project(const sim::Vec3& p) const {
        const studio::Viewport* v = w->viewport();
        const float aspect = float(std::max(1, v->width())) / float(std::max(1, v->height()));
        const Eigen::Vector4f c = render::monoEye(v->camera(), aspect).viewProjection * p.cast<float>().homogeneous();
        return {int((c.x() / c.w() + 1) * 0.5f * float(v->width())),
                int((1 - c.y() / c.w()) * 0.5f * float(v->height()))};
    }
    /// A right drag over the viewport by `by` pixels: the camera orbits.
    void orbit(QPoint by) {
        const QPoint c(w->viewport()->width() / 2, w->viewport()->height() / 2);
        viewportDrag(c, c + by, Qt::RightButton);
        ++actions;
    }
    double since(QElapsedTimer& t) const { return double(t.elapsed()) / 1000.0; }
};

/// The hepatocystic anatomy written by code, as bought anatomy arrives: the gallbladder, the
/// ducts and the artery with their atlas in one folder, the liver in another.
fs::path writeBoughtAnatomy(const fs::path& dir) {
    QProcess studio;
    studio.start(VISCERA_STUDIO_EXE,
                 {"sample", "hepatocystic", "-o", QString::fromStdString((dir / "calot").string())});
    EXPECT_TRUE(studio.waitForFinished(60000));
    EXPECT_EQ(studio.exitCode(), 0) << studio.readAllStandardError().toStdString();
    fs::create_directories(dir / "liver");
    fs::rename(dir / "calot" / "liver.obj", dir / "liver" / "liver.obj");
    return dir;
}

/// A two-handed console session over the built case, as a trainee's device records it (device
/// frame: metres from each master's workspace centre; the case maps them with each instrument's
/// motion scale from its rest tip, through its robotic port): the left grasper takes the fundus
/// and lifts it; then the right arm's clip applier fires a clip at each clip site (unless
/// `withClips` is false: it stays at rest), its button hands the arm to the scissors, which come
/// down across the duct at its cut line, turned so that their blades shut across it, and close;
/// then the same across the artery.
/// Returns the CSV text (haptics::Trajectory's format) and, in `afterClips`, the time the clips are
/// on and the scissors start.
std::string consoleSession(const studio::Project& p, bool withClips, double* afterClips, double* end,
                           double* afterHook = nullptr) {
    const auto& ins = p.scene.interaction->instruments; // grasper, hook, clip applier, scissors (the Add order)
    constexpr size_t kHook = 1, kClipper = 2, kScissors = 3;
    const sim::AssessmentDesc& a = *p.scene.assessment;
    auto restOf = [&](size_t i) { return sim::InstrumentTrack::parse(ins[i].trackText, "track").keys().front(); };
    struct Row {
        double t;
        int arm;
        sim::Vec3 device;
        Eigen::Quaterniond q;
        double grip;
        int buttons;
        int pedals = kPedalsIdle;
    };
    std::vector<Row> rows;
    const Eigen::Quaterniond none = Eigen::Quaterniond::Identity();
    auto device = [&](size_t i, const sim::Vec3& tip) {
        return sim::Vec3((tip - restOf(i).position) / ins[i].device.motionScale);
    };
    auto shaft = [&](size_t i, const sim::Vec3& tip) { return sim::Vec3((tip - ins[i].port.position).normalized()); };
    // left: the grasper comes down on the fundus along its shaft, closes on it and lifts it 13 mm
    // (the retraction that opens Calot's triangle), holding it to the end
    const sim::Vec3 hold = kFundus + sim::Vec3(0, 0, 0.003), along = shaft(0, hold);
    const sim::Vec3 lifted = hold + sim::Vec3(0, 0, 0.013);
    rows.push_back({0, 0, sim::Vec3::Zero(), none, 1.0, 0});
    rows.push_back({0.8, 0, device(0, hold - 0.04 * along), none, 1.0, 0});
    rows.push_back({2.0, 0, device(0, hold), none, 1.0, 0});
    rows.push_back({2.3, 0, device(0, hold), none, 0.05, 0}); // the jaws shut: the grasp
    rows.push_back({3.3, 0, device(0, lifted), none, 0.05, 0});
    const double t = 3.5; // the right arm starts once the fundus is up
    double r = t;
    rows.push_back({0, 1, sim::Vec3::Zero(), none, 1.0, 0});
    // right: the hook along the peritoneum's line over the duct (the third cut line), its tip
    // 1 mm in, the cut pedal held from its first point to its last at 8 mm/s
    {
        const std::vector<sim::Vec3>& line = a.cuts.at(2).line;
        auto in = [&](const sim::Vec3& q) { return sim::Vec3(q + 0.001 * shaft(kHook, q)); };
        const sim::Vec3 pre = line.front() - 0.012 * shaft(kHook, line.front());
        rows.push_back({r += 0.8, 1, device(kHook, pre), none, 1.0, 0});
        rows.push_back({r += 0.5, 1, device(kHook, in(line.front())), none, 1.0, 0});
        rows.push_back({r += 0.05, 1, device(kHook, in(line.front())), none, 1.0, 0, kPedalsCut});
        for (size_t k = 1; k < line.size(); ++k)
            rows.push_back({r += std::max(0.05, (line[k] - line[k - 1]).norm() / 0.008), 1, device(kHook, in(line[k])),
                            none, 1.0, 0, kPedalsCut});
        rows.push_back({r += 0.05, 1, device(kHook, in(line.back())), none, 1.0, 0});
        rows.push_back({r += 0.3, 1, device(kHook, line.back() - 0.012 * shaft(kHook, line.back())), none, 1.0, 0});
        if (afterHook) *afterHook = r;
        rows.push_back({r += 0.6, 1, sim::Vec3::Zero(), none, 1.0, 0});
        rows.push_back({r += 0.1, 1, sim::Vec3::Zero(), none, 1.0, 1}); // the arm's button: the clip applier
        rows.push_back({r += 0.1, 1, sim::Vec3::Zero(), none, 1.0, 0});
    }
    // the clip applier at each site (the duct's two, the artery's two), the tip 2 mm in
    if (withClips)
        for (const sim::ClipTarget& c : a.clips) {
            const sim::Vec3 d = shaft(kClipper, c.position), tip = c.position + 0.002 * d, pre = tip - 0.012 * d;
            rows.push_back({r += 0.8, 1, device(kClipper, pre), none, 1.0, 0});
            rows.push_back({r += 0.5, 1, device(kClipper, tip), none, 1.0, 0});
            rows.push_back({r += 0.2, 1, device(kClipper, tip), none, 0.05, 0}); // squeezed shut: the clip fires
            rows.push_back({r += 0.3, 1, device(kClipper, tip), none, 1.0, 0});
            rows.push_back({r += 0.3, 1, device(kClipper, pre), none, 1.0, 0});
        }
    rows.push_back({r += 0.6, 1, sim::Vec3::Zero(), none, 1.0, 0});
    rows.push_back({r += 0.1, 1, sim::Vec3::Zero(), none, 1.0, 1}); // the arm's button: the scissors
    rows.push_back({r += 0.1, 1, sim::Vec3::Zero(), none, 1.0, 0});
    *afterClips = r;
    // the scissors at each cut line in turn (the duct's, then the artery's): the line's middle,
    // their tip 6 mm past it, turned so that the blades' plane lies across the vessel
    const sim::Vec3 vesselAxes[] = {kDuctAxis, kArteryAxis};
    Eigen::Quaterniond turn = none;
    for (size_t c = 0; c < std::min<size_t>(a.cuts.size(), 2); ++c) {
        const std::vector<sim::Vec3>& line = a.cuts[c].line;
        const sim::Vec3 mid = 0.5 * (line.front() + line.back());
        const sim::Vec3 d = shaft(kScissors, mid), tip = mid + 0.006 * d, pre = mid - 0.012 * d;
        const sim::Vec3 y0 = Eigen::Quaterniond::FromTwoVectors(sim::Vec3::UnitX(), d) * sim::Vec3::UnitY();
        const sim::Vec3 across = (vesselAxes[c] - vesselAxes[c].dot(d) * d).normalized();
        const double roll = std::atan2(y0.cross(across).dot(d), y0.dot(across));
        turn = Eigen::Quaterniond(Eigen::AngleAxisd(roll, restOf(kScissors).direction.normalized()));
        rows.push_back({r += 0.3, 1, sim::Vec3::Zero(), turn, 1.0, 0});
        rows.push_back({r += 0.8, 1, device(kScissors, pre), turn, 1.0, 0});
        rows.push_back({r += 0.5, 1, device(kScissors, tip), turn, 1.0, 0});
        rows.push_back({r += 0.2, 1, device(kScissors, tip), turn, 0.05, 0}); // the blades shut: the cut
        rows.push_back({r += 0.3, 1, device(kScissors, tip), turn, 1.0, 0});
        rows.push_back({r += 0.3, 1, device(kScissors, pre), turn, 1.0, 0});
        rows.push_back({r += 0.6, 1, sim::Vec3::Zero(), turn, 1.0, 0});
    }
    rows.push_back({r + 0.7, 0, device(0, lifted), none, 0.05, 0});
    rows.push_back({r + 0.7, 1, sim::Vec3::Zero(), turn, 1.0, 0});
    *end = r + 0.7;
    std::string csv = "# viscera-trajectory 1\n# A cholecystectomy step on the console (made by the GUI test)\n"
                      "t,arm,x,y,z,qw,qx,qy,qz,grip,buttons,pedals\n";
    char line_[256];
    for (int arm = 0; arm < 2; ++arm)
        for (const Row& k : rows) {
            if (k.arm != arm) continue;
            std::snprintf(line_, sizeof line_, "%.3f,%d,%.5f,%.5f,%.5f,%.6f,%.6f,%.6f,%.6f,%.3f,%d,%d\n", k.t, k.arm,
                          k.device.x(), k.device.y(), k.device.z(), k.q.w(), k.q.x(), k.q.y(), k.q.z(), k.grip,
                          k.buttons, k.pedals);
            csv += line_;
        }
    return csv;
}

/// The build, step by step (each a stage of the artist's work, in order).
struct CholeSteps : CholeFixture {
    // what the steps hand on
    fs::path bought, dir, reference, out, session;
    QString trust;
    double afterClips = 0, end = 0, afterHook = 0;
    QElapsedTimer clock;
    /// 1. File → New project…: the folder typed into the dialog.
    void newProject() {
        dir = scratch.dir / "cholecystectomy";
        fs::create_directories(dir);
        typeIntoFileDialog(QString::fromStdString(dir.string()),
                           [&] { w->findChild<QAction*>("actionNewProject")->trigger(); });
        ASSERT_TRUE(test::waitFor([&] { return w->document()->hasProject(); }, 10000));
        w->preview()->setPaused(true); // the scene drawn at rest: picks land on rest positions
        steps()->task().setProgram(VISCERA_STUDIO_EXE);
        w->exportRunner()->setProgram(VISCERA_STUDIO_EXE);
        w->rehearsePanel()->rehearsal()->exportRunner().setProgram(VISCERA_STUDIO_EXE);
        ASSERT_TRUE(model().bodies.empty()) << "a new project has no placeholder body";
    }
    /// 2. File → Import anatomy…: every file of the bought folder (Ctrl+A, Open), metres as guessed.
    void importAnatomy() {
        QSettings().setValue("studio/anatomyFolder", QString::fromStdString((bought / "calot").string()));
        clock.start();
        steps()->importAction()->trigger();
        ++actions;
        QFileDialog* dlg = nullptr;
        ASSERT_TRUE(
            test::waitFor([&] { return (dlg = w->findChild<QFileDialog*>("importAnatomyDialog")) != nullptr; }, 5000));
        auto* list = dlg->findChild<QListView*>("listView");
        ASSERT_TRUE(test::waitFor([&] { return list->model()->rowCount(list->rootIndex()) == 5; }, 5000))
            << "four parts and their atlas";
        list->setFocus();
        QTest::keyClick(list, Qt::Key_A, Qt::ControlModifier);
        clickButton(dlg->findChild<QDialogButtonBox*>("buttonBox")->button(QDialogButtonBox::Open));
        ++actions;
        ASSERT_TRUE(test::waitFor([&] { return steps()->placementDialog() != nullptr; }, 60000))
            << steps()->task().output().toStdString();
        EXPECT_EQ(steps()->placementDialog()->guessedUnit(), bake::LengthUnit::Metre);
        clickButton(steps()->placementDialog()->findChild<QPushButton*>("importButton"));
        ASSERT_TRUE(test::waitFor([&] { return model().bodies.size() == 1; }, 60000))
            << w->log()->toPlainText().toStdString();
        timings.emplace_back("import", since(clock));
        ASSERT_EQ(model().bodies[0].mesh.remesh.parts.size(), 4u);
    }
    /// 3. Mesh → Make simulation-ready…: 200 voxels along the longest axis (the 1.5 mm artery
    /// needs them), openings up to 12 mm filled (the open ducts become solid, not hollow shells),
    /// Run, Apply.
    void makeSimulationReady() {
        clock.restart();
        steps()->simulationReadyAction()->trigger();
        ++actions;
        ASSERT_TRUE(test::waitFor([&] { return steps()->settingsDialog() != nullptr; }, 10000));
        auto* voxels = steps()->settingsDialog()->findChild<QSpinBox*>("voxels");
        voxels->selectAll();
        QTest::keyClicks(voxels, "200");
        actions += 2;
        auto* fill = steps()->settingsDialog()->findChild<QDoubleSpinBox*>("fillOpenings");
        ASSERT_NE(fill, nullptr);
        fill->setFocus();
        fill->selectAll();
        QTest::keyClicks(fill, "12");
        actions += 2;
        shot("chole_simulation_ready_settings");
        clickButton(steps()->settingsDialog()->findChild<QPushButton*>("runRemesh"));
        ASSERT_TRUE(
            test::waitFor([&] { return steps()->resultDialog() && steps()->resultDialog()->isVisible(); }, 240000))
            << "no remesh result: " << steps()->task().output().toStdString();
        EXPECT_THAT(steps()->resultDialog()->findChild<QLabel*>("remeshFigures")->text().toStdString(),
                    HasSubstr("closed yes, manifold yes"));
        clickButton(steps()->resultDialog()->findChild<QPushButton*>("applyRemesh"));
        EXPECT_EQ(model().bodies[0].mesh.remesh.params.voxelCount, 200);
        EXPECT_DOUBLE_EQ(model().bodies[0].mesh.remesh.params.fillOpenings, 0.012);
        timings.emplace_back("make simulation-ready", since(clock));
        if (QDialog* settings = steps()->settingsDialog(); settings && settings->isVisible())
            clickButton(settings->findChild<QDialogButtonBox*>()->button(QDialogButtonBox::Close));
    }
    /// 4. The body's tet and triangle sizes (3 mm: the 5 mm duct gets tets across it), typed in
    /// the Properties dock; then Mesh → Tetrahedralize…, taking the substeps the check asks for.
    void tetrahedralize() {
        raise("propertiesDock");
        typeField(find<QLineEdit>("facet_size_mm"), "3");
        typeField(find<QLineEdit>("cell_size_mm"), "3");
        EXPECT_DOUBLE_EQ(model().bodies[0].mesh.meshing.cellSize, 0.003);
        EXPECT_DOUBLE_EQ(model().bodies[0].mesh.meshing.facetSize, 0.003);
        clock.restart();
        steps()->tetrahedralizeAction()->trigger();
        ++actions;
        ASSERT_TRUE(test::waitFor([&] { return !steps()->task().running() && steps()->resultDialog(); }, 240000));
        QString meshed = steps()->resultDialog()->findChild<QLabel*>("meshingFigures")->text();
        for (int round = 0; round < 3 && meshed.contains("unstable"); ++round) {
            clickButton(steps()->resultDialog()->findChild<QPushButton*>("fixSubsteps"));
            ASSERT_TRUE(test::waitFor([&] { return !steps()->task().running() && steps()->resultDialog(); }, 240000));
            meshed = steps()->resultDialog()->findChild<QLabel*>("meshingFigures")->text();
        }
        EXPECT_THAT(meshed.toStdString(), HasSubstr("0 inverted"));
        EXPECT_THAT(meshed.toStdString(), HasSubstr("surface point(s) the first refinement missed were seeded"))
            << "the thin artery, seeded";
        EXPECT_FALSE(meshed.contains("unstable")) << meshed.toStdString();
        timings.emplace_back("tetrahedralize", since(clock));
        std::printf("tetrahedralized: %s\n", meshed.section('\n', 0, 0).toStdString().c_str());
        shot("chole_tetrahedralize_result");
        steps()->resultDialog()->close();
        ASSERT_TRUE(test::waitFor([&] { return w->viewport()->meshCount() > 0; }, 120000))
            << "the preview draws the body";
        shot("chole_tetrahedralized");
    }
    /// 5. The body renamed in the project tree: F2, the name, Enter.
    void renameBody() {
        auto* tree = w->projectTree();
        tree->setFocus();
        QTest::keyClick(tree, Qt::Key_F2);
        QInputDialog* rename = nullptr;
        ASSERT_TRUE(
            test::waitFor([&] { return (rename = w->findChild<QInputDialog*>("renameBodyDialog")) != nullptr; }, 5000));
        auto* nameEdit = rename->findChild<QLineEdit*>();
        nameEdit->selectAll();
        QTest::keyClicks(nameEdit, "calot");
        QTest::keyClick(nameEdit, Qt::Key_Return);
        actions += 3;
        ASSERT_EQ(model().bodies[0].scene.name, "calot");
        ASSERT_TRUE(test::waitFor([&] { return nearest(kGallTop, "calot").x() >= 0; }, 60000))
            << "the renamed body drawn";
    }
    /// 6. Held where it is attached: a drag along the gallbladder's top (its bed in the liver),
    /// one along the common bile duct, one over the artery's proximal end; seen from above (a right drag
    /// orbits the camera up).
    void holdWhereAttached() {
        orbit(QPoint(0, 70));
        raise("propertiesDock");
        clickButton(find<QToolButton>("holdTissueButton"));
        ASSERT_TRUE(w->holdTool()->action()->isChecked());
        typeField(find<QLineEdit>("hold_margin_mm"), "6");
        auto dragOn = [&](const sim::Vec3& a, const sim::Vec3& b, const char* what) {
            double ga = 0, gb = 0;
            const QPoint pa = nearest(a, "calot", &ga), pb = nearest(b, "calot", &gb);
            ASSERT_LT(ga, 0.004) << what << ": its start is in view";
            ASSERT_LT(gb, 0.004) << what << ": its end is in view";
            if (pa == pb)
                viewportClick(pa);
            else
                viewportDrag(pa, pb);
            ++actions;
        };
        dragOn(kGallTop, kGallTopFundus, "the gallbladder's top");
        dragOn(kBileDuctNear, kBileDuctFar, "the common bile duct");
        // the artery's proximal stretch, where it leaves the hepatic artery, with a 3 mm margin
        typeField(find<QLineEdit>("hold_margin_mm"), "3");
        dragOn(onArtery(0.0), onArtery(0.14), "the artery's proximal end");
        ASSERT_EQ(model().bodies[0].fixedBoxes.size(), 3u);
        for (const sim::Vec3& free : {kClipNear, kClipFar, kCut, kArteryClipNear, kArteryClipFar, kArteryCut})
            for (const auto& box : model().bodies[0].fixedBoxes)
                EXPECT_FALSE((free.array() >= box[0].array()).all() && (free.array() <= box[1].array()).all());
        shot("chole_held");
        w->holdTool()->action()->setChecked(false);
    }
    /// 7. The assessment's targets: two clip sites on the duct and two on the artery (one clip
    /// each, 4 mm), a cut line across each between its clips (4 mm radius).
    void pickTargets() {
        raise("assessmentDock");
        auto* targetTool = w->targetTool();
        auto* targets = w->assessmentPanel()->targetPanel();
        auto choose = [&](studio::TargetTool::Pick pick) {
            clickButton(targets->findChild<QToolButton*>(targetTool->action(pick)->objectName() + "Button"));
            ASSERT_EQ(targetTool->pick(), pick);
        };
        choose(studio::TargetTool::Pick::ClipSite);
        for (const sim::Vec3& site : {kClipNear, kClipFar, kArteryClipNear, kArteryClipFar}) {
            double gap = 0;
            const QPoint at = nearest(site, "calot", &gap);
            ASSERT_LT(gap, 0.003) << "the clip site is in view";
            viewportClick(at);
            ++actions;
        }
        ASSERT_EQ(model().scene.assessment->clips.size(), 4u) << targets->errorLabel()->text().toStdString();
        for (int c = 1; c <= 4; ++c) {
            typeCell(targets->table(), targets->row(QString("clip %1").arg(c), "count"), studio::TargetPanel::Value,
                     "1");
            typeCell(targets->table(), targets->row(QString("clip %1").arg(c), "tolerance (mm)"),
                     studio::TargetPanel::Value, "4");
        }
        choose(studio::TargetTool::Pick::CutLine);
        // a drag across each vessel, from the surface point nearest one side to the nearest the other:
        // across the duct level, across the thin artery as the camera sees it
        const sim::Vec3 view = (w->viewport()->camera().target - w->viewport()->camera().position).cast<double>();
        for (const auto& [at, across, half] :
             {std::tuple{kCut, sim::Vec3(kDuctAxis.cross(sim::Vec3::UnitZ()).normalized()), 0.004},
              std::tuple{kArteryCut, sim::Vec3(kArteryAxis.cross(view).normalized()), 0.0025}}) {
            double ga = 0, gb = 0;
            const QPoint a = nearest(at - half * across, "calot", &ga), b = nearest(at + half * across, "calot", &gb);
            ASSERT_GE(a.x(), 0);
            viewportDrag(a, b);
            ++actions;
        }
        ASSERT_EQ(model().scene.assessment->cuts.size(), 2u) << targets->errorLabel()->text().toStdString();
        // the peritoneum's line: a drag along the duct's top, where the hook opens the peritoneum
        {
            double ga = 0, gb = 0;
            const QPoint a = nearest(onDuct(0.15), "calot", &ga), b = nearest(onDuct(0.7), "calot", &gb);
            ASSERT_LT(ga, 0.004);
            ASSERT_LT(gb, 0.004);
            viewportDrag(a, b);
            ++actions;
        }
        ASSERT_EQ(model().scene.assessment->cuts.size(), 3u) << targets->errorLabel()->text().toStdString();
        for (const char* cut : {"cut 1", "cut 2", "cut 3"})
            typeCell(targets->table(), targets->row(cut, "radius (mm)"), studio::TargetPanel::Value, "4");
        const sim::AssessmentDesc& a = *model().scene.assessment;
        EXPECT_EQ(a.clips[0].count, 1);
        EXPECT_DOUBLE_EQ(a.clips[1].tolerance, 0.004);
        EXPECT_LT((a.clips[0].position - kClipNear).norm(), 0.004);
        EXPECT_LT((a.clips[2].position - kArteryClipNear).norm(), 0.003) << "on the artery";
        EXPECT_LT((a.clips[3].position - kArteryClipFar).norm(), 0.003) << "on the artery";
        for (const sim::Vec3& p : a.cuts[1].line)
            EXPECT_LT((p - kArteryCut).norm(), 0.006) << "the second cut line lies across the artery";
        EXPECT_GT((a.cuts[2].line.back() - a.cuts[2].line.front()).norm(), 0.012) << "the third along the duct";
        EXPECT_DOUBLE_EQ(a.cuts[0].radius, 0.004);
        shot("chole_targets");
        targetTool->action(targetTool->pick())->setChecked(false);
    }
    /// 8. The peritoneum over Calot's triangle: Add tissue layer from the body's context menu in
    /// the project tree, one subdivision and its region typed in Properties (the box around the
    /// cystic duct, the artery and the gallbladder's neck). The hook will open it; the scissors
    /// divide it with the vessels under it.
    void peritoneum() {
        auto* tree = w->projectTree();
        QTreeWidgetItem* body = nullptr;
        for (QTreeWidgetItemIterator it(tree); *it && !body; ++it)
            if ((*it)->text(0) == "calot") body = *it;
        ASSERT_NE(body, nullptr);
        tree->scrollToItem(body);
        contextMenu(tree, body, "addLayerAction");
        actions += 2;
        ASSERT_EQ(model().surfaces.size(), 1u) << tree->lastRefusal().toStdString();
        raise("propertiesDock");
        typeField(find<QLineEdit>("subdivide"), "1"); // 1.5 mm edges: the hook opens it along its pass
        typeField(find<QLineEdit>("region_min"), kPeritoneumMin);
        typeField(find<QLineEdit>("region_max"), kPeritoneumMax);
        ASSERT_TRUE(model().surfaces[0].region.has_value());
        EXPECT_EQ(model().surfaces[0].scene.attachTo, "calot");
        EXPECT_DOUBLE_EQ((*model().surfaces[0].region)[1].y(), -0.038);
        EXPECT_EQ(model().surfaces[0].subdivide, 1);
        ASSERT_TRUE(
            test::waitFor([&] { return nearest(kCut, model().surfaces[0].scene.name.c_str()).x() >= 0; }, 120000))
            << "the layer drawn over the duct; log: " << w->log()->toPlainText().right(3000).toStdString();
        shot("chole_peritoneum");
    }
    /// 9. Surroundings: the liver imported (its unit guessed), an abdominal wall around it all.
    void surroundings() {
        raise("surroundingsDock");
        auto* surroundings = w->findChild<studio::SurroundingsPanel*>("surroundingsPanel");
        QSettings().setValue("studio/anatomyFolder", QString::fromStdString((bought / "liver").string()));
        clickButton(surroundings->importButton());
        QFileDialog* liverDialog = nullptr;
        ASSERT_TRUE(test::waitFor(
            [&] {
                return (liverDialog = w->findChild<QFileDialog*>("sceneryImportDialog")) && liverDialog->isVisible();
            },
            5000));
        auto* liverName = liverDialog->findChild<QLineEdit*>("fileNameEdit");
        liverName->setFocus();
        QTest::keyClicks(liverName, "liver.obj");
        ++actions;
        clickButton(liverDialog->findChild<QDialogButtonBox*>("buttonBox")->button(QDialogButtonBox::Open));
        ASSERT_TRUE(test::waitFor([&] { return model().scenery.size() == 1; }, 10000))
            << surroundings->errorLabel()->text().toStdString();
        clickButton(w->findChild<QPushButton*>("addSceneryWall"));
        ASSERT_EQ(model().scenery.size(), 2u);
        typeField(find<QLineEdit>("scenery_name"), "abdominal_wall");
        typeField(find<QLineEdit>("scenery_start"), "0 -0.2 0");
        typeField(find<QLineEdit>("scenery_end"), "0 0.15 0");
        typeField(find<QLineEdit>("scenery_radius_mm"), "150");
        ASSERT_EQ(model().scenery[1].name, "abdominal_wall") << surroundings->errorLabel()->text().toStdString();
        EXPECT_DOUBLE_EQ(model().scenery[1].radius, 0.15);
        ASSERT_TRUE(test::waitFor([&] { return over("abdominal_wall").x() >= 0; }, 60000)) << "the wall drawn";
    }
    /// 10. Instruments: a grasper on the left master, the energy hook, the clip applier and the
    /// scissors on the right (its button hands the arm from one to the next), each port clicked on
    /// the wall where it reaches the task's targets; the clip applier's jaws 6 mm (the duct's width).
    void instrumentsAndPorts() {
        raise("instrumentDock");
        auto* instruments = w->findChild<studio::InstrumentPanel*>("instrumentPanel");
        for (auto kind : {sim::InstrumentDesc::Kind::Grasper, sim::InstrumentDesc::Kind::EnergyHook,
                          sim::InstrumentDesc::Kind::ClipApplier, sim::InstrumentDesc::Kind::Scissors}) {
            QComboBox* box = instruments->addKindBox();
            box->setCurrentIndex(box->findData(static_cast<int>(kind)));
            ++actions;
            clickButton(instruments->addButton());
        }
        ASSERT_TRUE(model().scene.interaction.has_value());
        const auto& ins = model().scene.interaction->instruments;
        ASSERT_EQ(ins.size(), 4u);
        EXPECT_EQ(ins[0].device.hand, "left");
        for (size_t i = 1; i < 4; ++i)
            EXPECT_EQ(ins[i].device.hand, "right");
        EXPECT_EQ(ins[2].target, "calot") << "the clip applier clips the one body";
        const auto& tissues = model().scene.interaction->tissues;
        ASSERT_EQ(tissues.size(), 2u) << "the hook and the scissors cut the peritoneum and the body under it";
        EXPECT_EQ(tissues[0].layer, model().surfaces[0].scene.name);
        EXPECT_EQ(tissues[1].layer, "calot");
        EXPECT_DOUBLE_EQ(tissues[1].ignitionC, studio::kCoveredBodyIgnitionC)
            << "the hook opens the layer, not the duct";
        instruments->list()->setCurrentRow(2);
        ++actions;
        typeField(instruments->field("jaw_length"), "0.006");
        EXPECT_DOUBLE_EQ(ins[2].jawLength, 0.006);
        // Place port (the toolbar's button) on, each instrument chosen in the dock, a click on the wall
        clickAction(w->portTool()->action());
        ASSERT_TRUE(w->portTool()->action()->isChecked());
        std::vector<sim::Vec3> rightTargets = {kClipNear, kClipFar, kCut, kArteryClipNear, kArteryClipFar, kArteryCut};
        for (const sim::Vec3& p : model().scene.assessment->cuts[2].line)
            rightTargets.push_back(p);
        for (int i = 0; i < 4; ++i) {
            instruments->list()->setCurrentRow(i);
            ++actions;
            ASSERT_EQ(w->portTool()->current(), i);
            const sim::Vec3 rest =
                sim::InstrumentTrack::parse(ins[size_t(i)].trackText, "track").keys().front().position;
            const int width = w->viewport()->width(), height = w->viewport()->height();
            const QPoint at =
                portPoint(ins[size_t(i)].port, rest, i == 0 ? std::vector<sim::Vec3>{kFundus} : rightTargets,
                          i == 0 ? QPoint(0, height / 2) : QPoint(width, height / 2));
            ASSERT_GE(at.x(), 0) << "a wall point whose port reaches instrument " << i << "'s targets";
            viewportClick(at);
            ++actions;
            const auto [reached, total] = w->portTool()->reachCounts();
            EXPECT_EQ(reached, total) << "instrument " << i << "'s port reaches its task points";
        }
        shot("chole_ports");
        w->portTool()->action()->setChecked(false);
        // the console's arms hold the instruments: robotic ports (a remote centre of motion)
        for (int i = 0; i < 4; ++i) {
            instruments->list()->setCurrentRow(i);
            QComboBox* mode = instruments->modeBox();
            mode->setCurrentIndex(mode->findData(static_cast<int>(sim::PortMode::Robotic)));
            emit mode->activated(mode->currentIndex());
            actions += 2;
            EXPECT_EQ(ins[size_t(i)].port.mode, sim::PortMode::Robotic)
                << instruments->findChild<QLabel*>("instrumentError")->text().toStdString();
        }
    }
    /// 11. The laparoscope: on, its port clicked on the wall in front of the task, the studio
    /// camera flown to the duct (a middle drag pans it there, the wheel zooms in), "Set scope
    /// view from here", a forward-viewing (0°) optic.
    void laparoscope() {
        raise("scopeTaskDock");
        auto* scope = w->findChild<studio::ScopeTaskPanel*>("scopeTaskPanel");
        ASSERT_TRUE(test::waitFor([&] { return scope->presentBox()->isVisible(); }, 5000));
        clickButton(scope->presentBox());
        ASSERT_TRUE(model().scene.laparoscope.has_value())
            << scope->errorLabel()->text().toStdString() << " checked " << scope->presentBox()->isChecked()
            << " enabled " << scope->presentBox()->isEnabled() << " modal "
            << (QApplication::activeModalWidget() ? QApplication::activeModalWidget()->objectName().toStdString()
                                                  : "none")
            << " geometry " << scope->presentBox()->width() << "x" << scope->presentBox()->height() << " log "
            << w->log()->toPlainText().right(300).toStdString();
        ASSERT_EQ(w->portTool()->current(), studio::PortTool::kScopePort);
        clickAction(w->portTool()->action());
        {
            const auto& lap = *model().scene.laparoscope;
            const QPoint at = portPoint(lap.port, lap.tip, {kCut, kClipNear, kClipFar, kArteryCut},
                                        QPoint(w->viewport()->width() / 2, w->viewport()->height()));
            ASSERT_GE(at.x(), 0) << "a wall point for the scope's port";
            viewportClick(at);
            ++actions;
        }
        w->portTool()->action()->setChecked(false);
        {
            const QPoint from = project(0.5 * (kCut + kArteryCut)),
                         centre(w->viewport()->width() / 2, w->viewport()->height() / 2);
            ASSERT_GE(from.x(), 0);
            viewportDrag(from, centre, Qt::MiddleButton); // a pan: the duct to the middle
            ++actions;
            for (int notch = 0; notch < 6; ++notch) {
                QWheelEvent wheel(QPointF(centre), QPointF(w->viewport()->mapToGlobal(centre)), QPoint(),
                                  QPoint(0, 120), Qt::NoButton, Qt::NoModifier, Qt::NoScrollPhase, false);
                QCoreApplication::sendEvent(w->viewport()->canvasWindow()
                                                ? static_cast<QObject*>(w->viewport()->canvasWindow())
                                                : w->viewport()->canvasWidget(),
                                            &wheel);
                ++actions;
            }
            QCoreApplication::processEvents();
        }
        clickButton(scope->setViewButton());
        EXPECT_TRUE(scope->errorLabel()->text().isEmpty()) << scope->errorLabel()->text().toStdString();
        scope->opticBox()->setCurrentIndex(scope->opticBox()->findData(0.0));
        emit scope->opticBox()->activated(scope->opticBox()->currentIndex());
        ++actions;
        EXPECT_DOUBLE_EQ(model().scene.laparoscope->opticDeg, 0);
        shot("chole_scope_set");
    }
    /// 12. The task: title, instructions and four ordered steps.
    void task() {
        auto* scope = w->findChild<studio::ScopeTaskPanel*>("scopeTaskPanel");
        typeField(scope->titleField(), "Laparoscopic cholecystectomy: clip and divide the cystic duct and artery");
        typeField(scope->instructionsField(),
                  "Lift the fundus, open the peritoneum over the cystic duct with the hook, "
                  "clip the cystic duct and the cystic artery twice each at the marked "
                  "sites and cut each between its clips.");
        for (const char* step : {"Grasp the fundus with the left grasper and lift it",
                                 "Open the peritoneum along the cystic duct with the hook",
                                 "Clip the cystic duct and the cystic artery twice each",
                                 "Cut the duct, then the artery, between their clips with the scissors"}) {
            clickButton(scope->addStepButton());
            QLineEdit* editor = nullptr;
            for (QLineEdit* e : scope->stepsList()->viewport()->findChildren<QLineEdit*>())
                if (e->isVisible()) editor = e;
            ASSERT_NE(editor, nullptr);
            QTest::keyClicks(editor, step);
            QTest::keyClick(editor, Qt::Key_Return);
            actions += 2;
            for (int k = 0; k < 3; ++k)
                QCoreApplication::processEvents();
            QCoreApplication::sendPostedEvents(nullptr, QEvent::DeferredDelete);
        }
        EXPECT_EQ(model().scene.steps.size(), 4u);
        EXPECT_EQ(model().title, "Laparoscopic cholecystectomy: clip and divide the cystic duct and artery");
    }
    /// 13. The verdict's limits typed in the Assessment table.
    void limits() {
        raise("assessmentDock");
        QTableWidget* metrics = w->assessmentPanel()->table();
        for (const auto& [metric, limit] : std::vector<std::pair<QString, QString>>{{"completion_time_s", "30"},
                                                                                    {"clips_on_target", "4"},
                                                                                    {"clips_off_target", "0"},
                                                                                    {"cut_coverage", "0.8"}})
            typeCell(metrics, rowOf(metrics, metric), studio::AssessmentPanel::Limit, limit);
        EXPECT_TRUE(w->assessmentPanel()->errorLabel()->text().isEmpty())
            << w->assessmentPanel()->errorLabel()->text().toStdString();
        EXPECT_EQ(model().scene.assessment->metrics.size(), 4u);
    }
    /// 14. Rehearse in the studio with the console session (a replay of it), see PASS, keep it as
    /// the case's reference replay.
    void rehearseAndKeep() {
        session = scratch.dir / "console-session.csv";
        { std::ofstream(session) << consoleSession(model(), true, &afterClips, &end, &afterHook); }
        raise("rehearseDock");
        auto* rehearse = w->rehearsePanel();
        QComboBox* deviceBox = rehearse->deviceBox();
        deviceBox->setFocus();
        QTest::keyClick(deviceBox->lineEdit(), Qt::Key_A, Qt::ControlModifier);
        QTest::keyClicks(deviceBox->lineEdit(), "replay:" + QString::fromStdString(session.string()));
        actions += 2;
        clock.restart();
        {
            QSignalSpy done(rehearse->rehearsal(), &studio::Rehearsal::finished);
            clickButton(rehearse->startButton());
            ASSERT_TRUE(test::waitFor([&] { return !done.isEmpty(); }, 300000))
                << rehearse->status()->text().toStdString();
        }
        timings.emplace_back("rehearse", since(clock));
        const studio::Rehearsal::Outcome& rehearsed = rehearse->rehearsal()->outcome();
        ASSERT_TRUE(rehearsed.ran) << rehearsed.error.toStdString();
        ASSERT_TRUE(rehearsed.passed) << rehearsed.summary.join('\n').toStdString();
        EXPECT_TRUE(rehearse->verdict()->text().startsWith("PASS")) << rehearse->verdict()->text().toStdString();
        std::printf("rehearsed: %d frames, physics %.2f ms per frame\n", rehearsed.frames, rehearsed.physicsMs);
        shot("chole_rehearsed");
        typeField(rehearse->replayName(), "clip_and_divide");
        {
            QSignalSpy kept(rehearse->rehearsal(), &studio::Rehearsal::finished);
            clickButton(rehearse->keepButton());
            ASSERT_TRUE(test::waitFor([&] { return !kept.isEmpty(); }, 300000))
                << rehearse->status()->text().toStdString();
        }
        reference = dir / "replays" / "clip_and_divide.csv";
        ASSERT_TRUE(fs::exists(reference)) << rehearse->status()->text().toStdString();
        EXPECT_TRUE(rehearse->verdict()->text().startsWith("The kept replay: PASS"))
            << rehearse->verdict()->text().toStdString();
    }
    /// 15. Save (Ctrl+S) and File → Export case…, signed with a publisher key made on the way.
    void exportSigned() {
        clickAction(w->findChild<QAction*>("actionSave"));
        out = scratch.dir / "cholecystectomy.vcase";
        bool exported = false, exportOk = false;
        QObject::connect(w->exportRunner(), &studio::ExportRunner::finished, [&](bool ok, const QString&) {
            exportOk = ok;
            exported = true;
        });
        clock.restart();
        typeIntoFileDialog(QString::fromStdString(out.string()),
                           [&] { w->findChild<QAction*>("actionExportCase")->trigger(); });
        ASSERT_TRUE(
            test::waitFor([&] { return w->unsignedExportBox() && w->unsignedExportBox()->isVisible(); }, 10000));
        clickButton(w->unsignedExportBox()->findChild<QPushButton*>("makeKeyAndSign"));
        ASSERT_TRUE(test::waitFor([&] { return exported; }, 300000));
        ASSERT_TRUE(exportOk) << w->exportRunner()->output().toStdString();
        timings.emplace_back("export", since(clock));
        trust = QString::fromStdString(studio::publicKeyPathFor(studio::defaultPublisherKeyPath()).string());
    }
    /// 16. The player: the case verifies; the reference replay passes; without the clips the
    /// same session fails on clips_on_target. Frames through the laparoscope at the start, after
    /// the clips and after the cut.
    void playerVerdicts() {
        auto player = [&](const QStringList& args) {
            QProcess run;
            run.start(VISCERA_PLAYER_EXE, args + QStringList{"--trust", trust, "--state-dir",
                                                             QString::fromStdString((scratch.dir / "state").string())});
            EXPECT_TRUE(run.waitForFinished(300000));
            return std::pair{run.exitCode(),
                             QString::fromLocal8Bit(run.readAllStandardOutput() + run.readAllStandardError())};
        };
        const auto [verifyCode, verified] = player({"verify", QString::fromStdString(out.string())});
        EXPECT_EQ(verifyCode, 0) << verified.toStdString();
        const int frames = int(std::ceil((end + 0.5) * 60));
        clock.restart();
        const auto [passCode, passed] =
            player({"run", QString::fromStdString(out.string()), "--headless", "--device",
                    "replay:" + QString::fromStdString(reference.string()), "--frames", QString::number(frames)});
        timings.emplace_back("player run (reference)", since(clock));
        EXPECT_EQ(passCode, 0) << passed.toStdString();
        EXPECT_TRUE(passed.contains(QRegularExpression("verdict +PASS"))) << passed.toStdString();
        EXPECT_TRUE(passed.contains(QRegularExpression("contacts, 1 grasps;")))
            << "the fundus held: " << passed.toStdString();
        EXPECT_TRUE(passed.contains(QRegularExpression("cut [1-9][0-9]* fascia edges")))
            << "the hook opened the peritoneum: " << passed.toStdString();
        std::printf("%s\n", passed.section("step time", 1, 1)
                                .section('\n', 0, 0)
                                .prepend("reference: step time")
                                .toStdString()
                                .c_str());
        const fs::path unclipped = scratch.dir / "unclipped.csv";
        {
            double a2 = 0, e2 = 0;
            std::ofstream(unclipped) << consoleSession(model(), false, &a2, &e2);
        }
        const auto [failCode, failed] =
            player({"run", QString::fromStdString(out.string()), "--headless", "--device",
                    "replay:" + QString::fromStdString(unclipped.string()), "--frames", QString::number(frames)});
        EXPECT_TRUE(failed.contains(QRegularExpression("verdict +FAIL \\([^)]*clips_on_target")))
            << failed.toStdString();
        EXPECT_TRUE(failed.contains(QRegularExpression("clips_on_target 0 count \\(limit ≥ 4\\) FAIL")))
            << failed.toStdString();
        std::printf("%s\n", failed.section("step time", 1, 1)
                                .section('\n', 0, 0)
                                .prepend("unclipped: step time")
                                .toStdString()
                                .c_str());
        if (const char* dir = std::getenv("VISCERA_GUI_SHOTS"); dir && *dir)
            for (const auto& [name, seconds] :
                 std::vector<std::pair<QString, double>>{{"chole_scope_start", 0.5},
                                                         {"chole_scope_opened", afterHook},
                                                         {"chole_scope_clipped", afterClips},
                                                         {"chole_scope_cut", end}})
                player({"run", QString::fromStdString(out.string()), "--headless", "--device",
                        "replay:" + QString::fromStdString(reference.string()), "--frames",
                        QString::number(int(seconds * 60)), "--screenshot", QString(dir) + "/" + name + ".png"});
    }
};

} // namespace

TEST_F(CholeSteps, ACholecystectomyStepIsBuiltByGuiActionsAndItsCaseIsJudgedFairly) {
    bought = writeBoughtAnatomy(scratch.dir / "bought");
    using Step = void (CholeSteps::*)();
    for (Step step :
         {&CholeSteps::newProject, &CholeSteps::importAnatomy, &CholeSteps::makeSimulationReady,
          &CholeSteps::tetrahedralize, &CholeSteps::renameBody, &CholeSteps::holdWhereAttached,
          &CholeSteps::pickTargets, &CholeSteps::peritoneum, &CholeSteps::surroundings,
          &CholeSteps::instrumentsAndPorts, &CholeSteps::laparoscope, &CholeSteps::task, &CholeSteps::limits,
          &CholeSteps::rehearseAndKeep, &CholeSteps::exportSigned, &CholeSteps::playerVerdicts}) {
        (this->*step)();
        ASSERT_FALSE(HasFatalFailure());
    }
    std::printf("GUI actions: %d\n", actions);
    for (const auto& [step, seconds] : timings)
        std::printf("  %s: %.1f s\n", step.c_str(), seconds);
}
