// Drawing the assessment's targets on the anatomy [issue 57 item 2]: a drag along a surface
// paints a cut line snapped to it, a click picks a clip site or the vessel, two clicks the suture
// plane; each is one undo step through the Document (the scene reader's rules), a refused pick or
// typed value leaves the model unchanged and says why, undo restores; the targets are drawn in the
// viewport while the Assessment dock is open and listed, editable, in its target table.
#include "app/assessment_panel.hpp"
#include "app/document.hpp"
#include "app/main_window.hpp"
#include "app/paint_tools.hpp"
#include "app/target_panel.hpp"
#include "app/target_tool.hpp"
#include "app/viewport.hpp"
#include "gui_test_support.hpp"
#include "window_fixture.hpp"

#include <QAction>
#include <QDockWidget>
#include <QLabel>
#include <QLineEdit>
#include <QPushButton>
#include <QTableWidget>
#include <QToolButton>
#include <QUndoStack>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace {

using namespace viscera;
using studio::TargetPanel;
using studio::TargetTool;
using studio::Viewport;
using ::testing::HasSubstr;
using Pick = TargetTool::Pick;

struct TargetToolFixture : test::MainWindowFixture {
    TargetTool* tool = nullptr;
    TargetPanel* panel = nullptr;
    TargetToolFixture() : MainWindowFixture("viscera-gui-targets") {}
    void SetUp() override {
        MainWindowFixture::SetUp();
        tool = w->targetTool();
        ASSERT_NE(tool, nullptr);
        panel = w->assessmentPanel()->targetPanel();
        ASSERT_NE(panel, nullptr);
        open("rectum");
        ASSERT_TRUE(test::waitFor([&] { return w->viewport()->meshCount() > 0; }, 30000));
        w->findChild<QDockWidget*>("assessmentDock")->raise();
        QCoreApplication::processEvents();
    }
    const sim::AssessmentDesc& model() const { return *w->document()->project().scene.assessment; }
    QUndoStack* undo() { return w->document()->undoStack(); }
    /// Turns a pick on as a user does: the Assessment dock's button.
    void choose(Pick pick) {
        auto* b = panel->findChild<QToolButton*>(tool->action(pick)->objectName() + "Button");
        ASSERT_NE(b, nullptr);
        QTest::mouseClick(b, Qt::LeftButton);
        ASSERT_EQ(tool->pick(), pick);
        ASSERT_TRUE(w->viewport()->paintMode());
    }
    /// A horizontal run of `length` px whose every 10th pixel lies over a surface.
    std::pair<QPoint, QPoint> run(int length) const {
        const Viewport* v = w->viewport();
        for (int y = v->height() / 4; y < 3 * v->height() / 4; y += 8)
            for (int x = 10; x + length < v->width(); x += 20) {
                bool all = true;
                for (int dx = 0; dx <= length && all; dx += 10)
                    all = v->hitAt(QPoint(x + dx, y)).has_value();
                if (all) return {QPoint(x, y), QPoint(x + length, y)};
            }
        return {{-1, -1}, {-1, -1}};
    }
    void press(QPoint at) { viewportClick(at); }
    void dragAlong(QPoint from, QPoint to) { viewportDrag(from, to); }
    /// Types `text` into the value cell of `row` as a user does: F2, the text, Enter.
    void typeInto(int row, const QString& text) {
        QTableWidget* t = panel->table();
        ASSERT_GE(row, 0);
        t->setFocus();
        t->setCurrentCell(row, TargetPanel::Value);
        QTest::keyClick(t, Qt::Key_F2);
        auto* editor = t->viewport()->findChild<QLineEdit*>();
        ASSERT_NE(editor, nullptr) << "F2 opened the cell's editor";
        QTest::keyClick(editor, Qt::Key_A, Qt::ControlModifier);
        QTest::keyClicks(editor, text);
        QTest::keyClick(editor, Qt::Key_Return);
        QCoreApplication::processEvents();
        QCoreApplication::sendPostedEvents(nullptr, QEvent::DeferredDelete);
    }
    std::vector<std::string> layerNames() const {
        std::vector<std::string> names;
        for (const auto& m : w->viewport()->authoringLayer(Viewport::Layer::Targets))
            if (m.vertexCount() > 0) names.push_back(m.name);
        return names;
    }
};

TEST_F(TargetToolFixture, TheTargetsAreDrawnAndListedWhileTheAssessmentDockIsOpen) {
    ASSERT_TRUE(tool->shown());
    EXPECT_THAT(layerNames(), ::testing::ElementsAre("cut targets", "clip targets", "vessel target"));
    EXPECT_TRUE(w->viewport()->authoringLayer(Viewport::Layer::Port).empty())
        << "no port's dock in view: no workspace drawn over the targets";
    EXPECT_GE(panel->row("cut 1", "radius (mm)"), 0);
    EXPECT_EQ(panel->table()->item(panel->row("cut 1", "radius (mm)"), TargetPanel::Value)->text().toDouble(),
              model().cuts[0].radius * 1e3);
    EXPECT_EQ(panel->table()->item(panel->row("vessel", "body"), TargetPanel::Value)->text(), "vessel");
    test::saveShot("targets_dock");
    if (const char* dir = std::getenv("VISCERA_GUI_SHOTS"); dir && *dir)
        w->viewport()->grabFramebuffer().save(QString(dir) + "/targets_viewport.png");
    // another tab in front of the dock: the targets go from the viewport
    w->findChild<QDockWidget*>("plotsDock")->raise();
    QCoreApplication::processEvents();
    EXPECT_FALSE(tool->shown());
    EXPECT_TRUE(layerNames().empty());
}

TEST_F(TargetToolFixture, ADragAlongASurfaceDrawsACutLineAsOneUndoStep) {
    const auto [from, to] = run(200);
    ASSERT_GE(from.x(), 0) << "a run of surface across the view";
    choose(Pick::CutLine);
    const size_t before = model().cuts.size();
    const int steps = undo()->count();
    dragAlong(from, to);
    ASSERT_EQ(model().cuts.size(), before + 1) << panel->errorLabel()->text().toStdString();
    EXPECT_EQ(undo()->count(), steps + 1) << "one drag, one undo step";
    const sim::CutTarget& cut = model().cuts.back();
    EXPECT_GE(cut.line.size(), 3u);
    for (size_t i = 1; i < cut.line.size(); ++i)
        EXPECT_GE((cut.line[i] - cut.line[i - 1]).norm(), TargetTool::kStrokeStep - 1e-9);
    // the line is snapped to the surface: its first point is the surface point under the press
    const auto hit = w->viewport()->hitAt(from);
    ASSERT_TRUE(hit);
    EXPECT_LT((cut.line.front() - hit->rest.cast<double>()).norm(), 1e-5);
    EXPECT_EQ(cut.radius, tool->defaults().cutRadius);
    EXPECT_GE(panel->row(QString("cut %1").arg(before + 1), "line"), 0) << "listed in the dock";
    test::saveShot("target_cut_drawn");
    if (const char* dir = std::getenv("VISCERA_GUI_SHOTS"); dir && *dir)
        w->viewport()->grabFramebuffer().save(QString(dir) + "/target_cut_drawn_viewport.png");
    // a click without a drag is one point: refused, the model unchanged
    press(from);
    EXPECT_EQ(model().cuts.size(), before + 1);
    EXPECT_THAT(panel->errorLabel()->text().toStdString(), HasSubstr("at least 2 points"));
    undo()->undo();
    EXPECT_EQ(model().cuts.size(), before);
    QTest::keyClick(w->viewport(), Qt::Key_Escape);
    EXPECT_EQ(tool->pick(), Pick::None) << "Esc ends the tool";
    EXPECT_FALSE(w->viewport()->paintMode());
}

TEST_F(TargetToolFixture, ClicksPickAClipSiteTheVesselAndTheSuturePlane) {
    const QPoint at = over("fat");
    ASSERT_GE(at.x(), 0) << "the fat is in view";
    const auto hit = w->viewport()->hitAt(at);
    choose(Pick::ClipSite);
    const int steps = undo()->count();
    press(at);
    ASSERT_EQ(model().clips.size(), 2u) << panel->errorLabel()->text().toStdString();
    EXPECT_LT((model().clips[1].position - hit->rest.cast<double>()).norm(), 1e-6);
    EXPECT_EQ(model().clips[1].count, tool->defaults().clipCount);
    EXPECT_EQ(undo()->count(), steps + 1);
    // the vessel: a click on a body names it; the rule refuses what is not a body
    choose(Pick::Vessel);
    EXPECT_EQ(tool->action(Pick::ClipSite)->isChecked(), false) << "one pick at a time";
    press(at);
    EXPECT_EQ(model().vessel->body, "fat");
    EXPECT_EQ(undo()->count(), steps + 2);
    const QString why = tool->setVessel("pelvic_wall");
    EXPECT_THAT(why.toStdString(), HasSubstr("assessment.targets.vessel"));
    EXPECT_EQ(model().vessel->body, "fat") << "refused: unchanged";
    const QPoint other = run(200).second;
    ASSERT_GE(other.x(), 0);
    // the suture plane: two clicks, one step; halfway between them, normal from the first to the second
    choose(Pick::SuturePlane);
    const auto a = w->viewport()->hitAt(at), b = w->viewport()->hitAt(other);
    press(at);
    EXPECT_TRUE(tool->firstPlanePoint().has_value());
    EXPECT_FALSE(model().suture.has_value()) << "not taken before the second click";
    press(other);
    ASSERT_TRUE(model().suture.has_value()) << panel->errorLabel()->text().toStdString();
    const sim::Vec3 pa = a->rest.cast<double>(), pb = b->rest.cast<double>();
    EXPECT_LT((model().suture->planePoint - 0.5 * (pa + pb)).norm(), 1e-6);
    EXPECT_LT((model().suture->planeNormal - (pb - pa).normalized()).norm(), 1e-6);
    EXPECT_EQ(undo()->count(), steps + 3);
    EXPECT_NE(tool->setSuturePlane(pa, pa), "") << "the same point twice is refused";
    test::saveShot("targets_picked");
    undo()->undo();
    undo()->undo();
    undo()->undo();
    EXPECT_FALSE(model().suture.has_value());
    EXPECT_EQ(model().vessel->body, "vessel");
    EXPECT_EQ(model().clips.size(), 1u);
}

TEST_F(TargetToolFixture, TypedValuesAndRemovalsAreUndoableAndRefusalsLeaveTheModelUnchanged) {
    const double radius = model().cuts[0].radius;
    const int steps = undo()->count();
    ASSERT_EQ(undo()->index(), steps);
    typeInto(panel->row("cut 1", "radius (mm)"), "3");
    EXPECT_DOUBLE_EQ(model().cuts[0].radius, 0.003);
    EXPECT_EQ(undo()->count(), steps + 1);
    typeInto(panel->row("cut 1", "radius (mm)"), "-2");
    EXPECT_THAT(panel->errorLabel()->text().toStdString(), HasSubstr("assessment.targets.cut[0].radius"));
    EXPECT_DOUBLE_EQ(model().cuts[0].radius, 0.003) << "refused: unchanged";
    EXPECT_EQ(panel->table()->item(panel->row("cut 1", "radius (mm)"), TargetPanel::Value)->text(), "3");
    typeInto(panel->row("clip 1", "count"), "two");
    EXPECT_THAT(panel->errorLabel()->text().toStdString(), HasSubstr("not a whole number"));
    typeInto(panel->row("clip 1", "count"), "3");
    EXPECT_EQ(model().clips[0].count, 3);
    EXPECT_EQ(undo()->count(), steps + 2);
    // the only clip site: a metric needs it, so it stays
    panel->table()->setCurrentCell(panel->row("clip 1", "count"), TargetPanel::Value);
    QTest::mouseClick(panel->removeButton(), Qt::LeftButton);
    EXPECT_THAT(panel->errorLabel()->text().toStdString(), HasSubstr("needs a clip target"));
    EXPECT_EQ(model().clips.size(), 1u);
    // a second one can go
    ASSERT_EQ(tool->addClipSite(model().clips[0].position + sim::Vec3(0.01, 0, 0)), "");
    panel->table()->setCurrentCell(panel->row("clip 2", "tolerance (mm)"), TargetPanel::Value);
    QTest::mouseClick(panel->removeButton(), Qt::LeftButton);
    EXPECT_EQ(model().clips.size(), 1u);
    EXPECT_EQ(undo()->count(), steps + 4);
    undo()->undo();
    EXPECT_EQ(model().clips.size(), 2u);
    while (undo()->index() > steps)
        undo()->undo();
    EXPECT_EQ(model().cuts[0].radius, radius);
    EXPECT_EQ(model().clips[0].count, 2);
}

// One viewport tool at a time, and the one that came on keeps the clicks: a paint tool taking
// over from a target pick (or a pick from the port tool) leaves the viewport in paint mode.
TEST_F(TargetToolFixture, TheToolThatComesOnKeepsTheViewportsClicks) {
    choose(Pick::ClipSite);
    w->paintTools()->stiffnessAction()->trigger();
    EXPECT_EQ(tool->pick(), Pick::None) << "the pick went off";
    EXPECT_TRUE(w->paintTools()->stiffnessAction()->isChecked());
    EXPECT_TRUE(w->viewport()->paintMode()) << "the paint tool still takes the drag";
    choose(Pick::CutLine);
    EXPECT_FALSE(w->paintTools()->stiffnessAction()->isChecked());
    EXPECT_TRUE(w->viewport()->paintMode());
    QTest::keyClick(w->viewport(), Qt::Key_Escape);
    EXPECT_FALSE(w->viewport()->paintMode());
}

} // namespace
