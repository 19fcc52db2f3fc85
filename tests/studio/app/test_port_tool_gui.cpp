// Placing trocar ports in the viewport [issue 57 item 1]: with "Place port" on, a click on a drawn
// surface moves the current port there (one undo step, a drag merges), a position the reader
// refuses leaves the model unchanged and says why, undo restores; the workspace cone and the
// task targets (green reached, red not) are drawn while a port is current; the shipped rectum's
// ports reach every target and a port moved away flags them, as the export check does.
#include "app/document.hpp"
#include "app/main_window.hpp"
#include "app/port_tool.hpp"
#include "app/viewport.hpp"
#include "gui_test_support.hpp"
#include "sim/scene/port_reach.hpp"
#include "window_fixture.hpp"

#include <QAction>
#include <QDockWidget>
#include <QListWidget>
#include <QSignalSpy>
#include <QUndoStack>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace {

using namespace viscera;
using studio::PortTool;
using studio::Viewport;
using ::testing::HasSubstr;

struct PortToolFixture : test::MainWindowFixture {
    PortTool* tool = nullptr;
    PortToolFixture() : MainWindowFixture("viscera-gui-ports") {}
    void SetUp() override {
        MainWindowFixture::SetUp();
        tool = w->portTool();
        ASSERT_NE(tool, nullptr);
        open("rectum");
        ASSERT_TRUE(test::waitFor([&] { return w->viewport()->meshCount() > 0; }, 30000));
        w->findChild<QDockWidget*>("instrumentDock")->raise(); // the ports of the dock in view
        QCoreApplication::processEvents();
    }
    const studio::Project& model() const { return w->document()->project(); }
    int instrument(const std::string& name) const {
        const auto& ins = model().scene.interaction->instruments;
        for (size_t i = 0; i < ins.size(); ++i)
            if (ins[i].name == name) return static_cast<int>(i);
        return -1;
    }
    const sim::PortDesc& port(int i) const { return model().scene.interaction->instruments[size_t(i)].port; }
    /// The first widget position (on a grid over the viewport) whose surface point the port
    /// tool may take for instrument `i`; none found: an invalid point.
    QPoint placeablePoint(int i) {
        Viewport* v = w->viewport();
        for (int y = v->height() / 8; y < v->height(); y += v->height() / 8)
            for (int x = v->width() / 8; x < v->width(); x += v->width() / 8) {
                const auto hit = v->hitAt(QPoint(x, y));
                if (!hit) continue;
                sim::InstrumentDesc in = model().scene.interaction->instruments[size_t(i)];
                const auto frame = sim::instrumentPortFrame(in);
                const sim::Vec3 p = hit->world.cast<double>();
                const double d = (frame->restTip - p).norm();
                if (d > in.port.insertionMin + 1e-3 && d < in.port.insertionMax - 1e-3) return {x, y};
            }
        return {-1, -1};
    }
};

TEST_F(PortToolFixture, TheShippedPortsReachEveryTargetAndTheWorkspaceIsDrawn) {
    EXPECT_TRUE(sim::unreachableTargets(model().scene).empty());
    const int hook = instrument("hook");
    ASSERT_GE(hook, 0);
    tool->setCurrent(PortTool::kNoPort);
    EXPECT_FALSE(tool->action()->isEnabled()) << "no port is current";
    // choosing the hook in the Instruments dock makes its port the current one
    auto* list = w->findChild<QListWidget*>("instrumentList");
    ASSERT_NE(list, nullptr);
    list->setCurrentRow(hook == 0 ? 1 : 0);
    list->setCurrentRow(hook);
    EXPECT_EQ(tool->current(), hook);
    EXPECT_TRUE(tool->action()->isEnabled());
    const auto [reached, total] = tool->reachCounts();
    EXPECT_GT(total, 10) << "the cut line sampled every 2 mm";
    EXPECT_EQ(reached, total);
    const auto& meshes = w->viewport()->authoringMeshes();
    ASSERT_EQ(meshes.size(), 2u);
    EXPECT_EQ(meshes[0].name, "port workspace");
    EXPECT_EQ(meshes[1].name, "port targets");
    test::saveShot("port_workspace_hook");
    if (const char* dir = std::getenv("VISCERA_GUI_SHOTS"); dir && *dir) // the viewport's own frame
        w->viewport()->grabFramebuffer().save(QString(dir) + "/port_workspace_hook_viewport.png");
    tool->setCurrent(PortTool::kNoPort);
    EXPECT_TRUE(w->viewport()->authoringMeshes().empty());
}

TEST_F(PortToolFixture, AClickOnASurfaceMovesThePortAsOneUndoStepAndUndoRestoresIt) {
    const int hook = instrument("hook");
    tool->setCurrent(hook);
    const QPoint at = placeablePoint(hook);
    ASSERT_GE(at.x(), 0) << "some surface point in view lies within the hook's insertion range";
    const sim::Vec3 before = port(hook).position;
    const int steps = w->document()->undoStack()->count();
    tool->action()->setChecked(true);
    EXPECT_TRUE(w->viewport()->paintMode());
    const auto hit = w->viewport()->hitAt(at);
    ASSERT_TRUE(hit);
    QWindow* canvas = w->viewport()->canvasWindow();
    QWidget* widget = w->viewport()->canvasWidget();
    if (canvas) {
        QTest::mousePress(canvas, Qt::LeftButton, {}, at);
        QTest::mouseRelease(canvas, Qt::LeftButton, {}, at);
    } else {
        QTest::mousePress(widget, Qt::LeftButton, {}, at);
        QTest::mouseRelease(widget, Qt::LeftButton, {}, at);
    }
    QCoreApplication::processEvents();
    EXPECT_EQ(w->document()->undoStack()->count(), steps + 1);
    EXPECT_LT((port(hook).position - hit->world.cast<double>()).norm(), 1e-6);
    w->document()->undoStack()->undo();
    EXPECT_EQ(port(hook).position, before);
    test::saveShot("port_placed_hook");
}

TEST_F(PortToolFixture, ADragIsOneStepAndARefusedPlaceLeavesTheModelUnchanged) {
    const int clipper = instrument("clipper");
    ASSERT_GE(clipper, 0);
    tool->setCurrent(clipper);
    const sim::Vec3 before = port(clipper).position;
    const int steps = w->document()->undoStack()->count();
    const int key = w->document()->newMergeKey();
    const sim::Vec3 a = before + sim::Vec3(0.005, 0, 0), b = before + sim::Vec3(0.01, 0.002, 0);
    EXPECT_EQ(tool->placeAt(a, key), "");
    EXPECT_EQ(tool->placeAt(b, key), "");
    EXPECT_EQ(w->document()->undoStack()->count(), steps + 1) << "one drag, one step";
    EXPECT_EQ(port(clipper).position, b);
    // 1 m away the clipper's rest tip lies outside the insertion range: refused, nothing changes
    QSignalSpy refusals(tool, &PortTool::refused);
    const QString why = tool->placeAt(b + sim::Vec3(0, 0, 1.0), w->document()->newMergeKey());
    EXPECT_THAT(why.toStdString(), HasSubstr("interaction.instruments["));
    EXPECT_THAT(why.toStdString(), HasSubstr("insertion"));
    EXPECT_EQ(port(clipper).position, b);
    EXPECT_EQ(w->document()->undoStack()->count(), steps + 1);
    EXPECT_NE(tool->placeAt(sim::Vec3(NAN, 0, 0), 0), "");
    w->document()->undoStack()->undo();
    EXPECT_EQ(port(clipper).position, before);
}

TEST_F(PortToolFixture, APortThatCannotReachItsTargetsIsFlaggedInRedAndByTheExportCheck) {
    const int clipper = instrument("clipper");
    tool->setCurrent(clipper);
    // the cone narrowed to 2° and the insertion stopped 1 mm past the rest tip (which lies above
    // the vessel): the clip site is out of reach
    sim::InstrumentDesc in = model().scene.interaction->instruments[size_t(clipper)];
    const auto rest = sim::instrumentPortFrame(in);
    ASSERT_TRUE(rest);
    in.port.maxAngleDeg = 2;
    in.port.insertionMax = std::max((rest->restTip - in.port.position).norm() + 0.001, in.port.insertionMin + 0.002);
    const auto frame = sim::instrumentPortFrame(in);
    ASSERT_TRUE(frame);
    const sim::Vec3 site = model().scene.assessment->clips.at(0).position;
    ASSERT_NE(sim::reachRule(*frame, site), "");
    ASSERT_EQ(w->document()->editInstrument("narrow", clipper, in), "");
    const auto [reached, total] = tool->reachCounts();
    EXPECT_LT(reached, total);
    const auto problems = sim::unreachableTargets(model().scene);
    ASSERT_FALSE(problems.empty());
    EXPECT_THAT(problems[0].message, HasSubstr("'clipper': its port cannot reach assessment.targets.clip[0]"));
    // a red cross: some overlay vertex of the targets mesh is red
    const auto& meshes = w->viewport()->authoringMeshes();
    ASSERT_EQ(meshes.size(), 2u);
    bool red = false;
    for (size_t k = 0; k + 3 < meshes[1].overlay.size(); k += 4)
        red = red || (meshes[1].overlay[k] > 0.9f && meshes[1].overlay[k + 1] < 0.2f);
    EXPECT_TRUE(red);
    test::saveShot("port_unreachable_clipper");
}

TEST_F(PortToolFixture, TheLaparoscopesPortIsPlacedTheSameWay) {
    tool->setCurrent(PortTool::kScopePort);
    ASSERT_TRUE(tool->currentFrame());
    const sim::Vec3 before = model().scene.laparoscope->port.position;
    const int steps = w->document()->undoStack()->count();
    EXPECT_EQ(tool->placeAt(before + sim::Vec3(0, 0.004, 0), w->document()->newMergeKey()), "");
    EXPECT_EQ(w->document()->undoStack()->count(), steps + 1);
    EXPECT_NEAR(model().scene.laparoscope->port.position.y(), before.y() + 0.004, 1e-12);
    w->document()->undoStack()->undo();
    EXPECT_EQ(model().scene.laparoscope->port.position, before);
}

// The gizmo [issue 57 item 1]: with "Place port" on, an x, y and z handle are drawn at the port;
// a left drag on the x handle (synthetic mouse events on the viewport) slides the port along x
// alone, one undo step, and is not taken by the surface under the handle; a drag far along it
// would take the hook's rest tip out of its insertion range: the reader refuses, the port stays
// at the last position taken and the rule is said; undo restores the port.
TEST_F(PortToolFixture, TheGizmoSlidesThePortAlongTheDraggedAxisAsOneUndoStep) {
    const int hook = instrument("hook");
    tool->setCurrent(hook);
    tool->action()->setChecked(true);
    QCoreApplication::processEvents();
    std::vector<std::string> names;
    for (const auto& m : w->viewport()->authoringMeshes())
        names.push_back(m.name);
    EXPECT_THAT(names, ::testing::IsSupersetOf({"port workspace", "port gizmo x", "port gizmo y", "port gizmo z"}));
    Viewport* v = w->viewport();
    const sim::Vec3 before = port(hook).position;
    const int steps = w->document()->undoStack()->count();
    const auto a = v->toScreen(before.cast<float>());
    const auto b = v->toScreen((before + 0.7 * PortTool::kGizmoLength * sim::Vec3::UnitX()).cast<float>());
    ASSERT_TRUE(a && b);
    const QPointF along = (*b - *a) / std::hypot((*b - *a).x(), (*b - *a).y());
    const QPoint grip = b->toPoint();
    ASSERT_EQ(tool->handleAt(grip), 0) << "the x handle is under the cursor";
    viewportDrag(grip, (*b + 30 * along).toPoint());
    EXPECT_EQ(w->document()->undoStack()->count(), steps + 1) << "one drag, one step";
    const sim::Vec3 moved = port(hook).position;
    EXPECT_GT(moved.x(), before.x() + 0.002) << "slid along +x";
    EXPECT_NEAR(moved.y(), before.y(), 1e-12);
    EXPECT_NEAR(moved.z(), before.z(), 1e-12);
    test::saveShot("port_gizmo_dragged");
    if (const char* dir = std::getenv("VISCERA_GUI_SHOTS"); dir && *dir)
        v->grabFramebuffer().save(QString(dir) + "/port_gizmo_dragged_viewport.png");
    // far along x: refused past the insertion range, the port at the last position taken
    QSignalSpy refusals(tool, &PortTool::refused);
    const auto c = v->toScreen((moved + 0.7 * PortTool::kGizmoLength * sim::Vec3::UnitX()).cast<float>());
    ASSERT_TRUE(c);
    ASSERT_EQ(tool->handleAt(c->toPoint()), 0);
    viewportDrag(c->toPoint(), (*c + 2000 * along).toPoint());
    ASSERT_FALSE(refusals.isEmpty()) << "a 2000 px drag takes the port metres away";
    EXPECT_THAT(refusals.last().at(0).toString().toStdString(), HasSubstr("insertion"));
    const sim::Vec3 last = port(hook).position;
    EXPECT_TRUE(last.allFinite());
    EXPECT_NEAR(last.y(), before.y(), 1e-12);
    EXPECT_EQ(sim::restTipError(
                  port(hook), sim::instrumentPortFrame(model().scene.interaction->instruments[size_t(hook)])->restTip),
              "")
        << "the port taken last is one the reader accepts";
    EXPECT_EQ(w->document()->undoStack()->count(), steps + 2);
    w->document()->undoStack()->undo();
    w->document()->undoStack()->undo();
    EXPECT_EQ(port(hook).position, before);
    tool->action()->setChecked(false);
    for (const auto& m : w->viewport()->authoringMeshes())
        EXPECT_EQ(m.name.rfind("port gizmo", 0), std::string::npos) << "the gizmo goes with the tool";
}

} // namespace
