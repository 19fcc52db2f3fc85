// Holding tissue where it is attached [issue 57 item 4]: with "Hold tissue" on, a click on a body
// (or on the fascia over it) holds the nodes around the point hit, a drag those along the stroke;
// each is one undo step adding a box to the body's "fixed" list; a click on a surrounding is
// refused and leaves the model unchanged; a refused margin leaves the field and the tool as they
// were; Release holds is one undo step; undo restores; the boxes are drawn while the tool is on.
#include "app/document.hpp"
#include "app/hold_tool.hpp"
#include "app/main_window.hpp"
#include "app/preview.hpp"
#include "app/properties_panel.hpp"
#include "app/viewport.hpp"
#include "gui_test_support.hpp"
#include "window_fixture.hpp"

#include <QAction>
#include <QDockWidget>
#include <QLabel>
#include <QLineEdit>
#include <QPlainTextEdit>
#include <QPushButton>
#include <QToolButton>
#include <QUndoStack>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace {

using namespace viscera;
using studio::HoldTool;
using ::testing::HasSubstr;

struct HoldToolFixture : test::MainWindowFixture {
    HoldTool* tool = nullptr;
    HoldToolFixture() : MainWindowFixture("viscera-gui-holds") {}
    void openSample(const std::string& name) {
        tool = w->holdTool();
        ASSERT_NE(tool, nullptr);
        open(name);
        ASSERT_TRUE(test::waitFor([&] { return w->viewport()->meshCount() > 0; }, 30000));
        w->findChild<QDockWidget*>("propertiesDock")->raise();
        QCoreApplication::processEvents();
    }
    const std::vector<std::array<sim::Vec3, 2>>& holds(int body) const {
        return w->document()->project().bodies[size_t(body)].fixedBoxes;
    }
    QUndoStack* undo() { return w->document()->undoStack(); }
    /// Selects body 0 as a user does (a click on it in the viewport) and turns the tool on with
    /// the Properties panel's button.
    void holdOn(QPoint onBody) {
        viewportClick(onBody);
        ASSERT_TRUE(test::waitFor([&] { return w->findChild<QToolButton*>("holdTissueButton") != nullptr; }, 5000));
        QTest::mouseClick(w->findChild<QToolButton*>("holdTissueButton"), Qt::LeftButton);
        ASSERT_TRUE(tool->action()->isChecked());
        ASSERT_TRUE(w->viewport()->paintMode());
    }
};

TEST_F(HoldToolFixture, AClickOrADragOnABodyHoldsItThereAsOneUndoStep) {
    openSample("organ-blob");
    const QPoint onBody = over(QString::fromStdString(w->document()->project().bodies[0].scene.name));
    ASSERT_GE(onBody.x(), 0) << "the organ is drawn";
    const auto before = holds(0);
    holdOn(onBody);
    const int steps = undo()->index();
    auto caughtUp = [&] { return w->preview()->snapshot().serial >= w->lastPreviewSubmit().first; };
    ASSERT_TRUE(test::waitFor(caughtUp, 60000));
    const int meshed = w->log()->toPlainText().count("preview: building meshes");
    viewportClick(onBody);
    ASSERT_EQ(holds(0).size(), before.size() + 1);
    ASSERT_TRUE(test::waitFor(caughtUp, 60000));
    EXPECT_TRUE(w->preview()->snapshot().error.isEmpty()) << w->preview()->snapshot().error.toStdString();
    EXPECT_EQ(w->log()->toPlainText().count("preview: building meshes"), meshed)
        << "a hold goes onto the meshes the preview built: no meshing again";
    EXPECT_EQ(undo()->index(), steps + 1) << "one click, one undo step";
    const auto& box = holds(0).back();
    EXPECT_NEAR(box[1].x() - box[0].x(), 2 * HoldTool::kDefaultMargin, 1e-9) << "a click: the point ± the margin";
    EXPECT_TRUE(test::waitFor([&] { return w->findChild<QLabel*>("heldCount") != nullptr; }, 5000));
    // a drag along the body: one box over the stroke, grown by the margin
    const QPoint from = onBody, to = onBody + QPoint(40, 0);
    ASSERT_TRUE(w->viewport()->hitAt(to).has_value());
    viewportDrag(from, to);
    ASSERT_EQ(holds(0).size(), before.size() + 2);
    EXPECT_EQ(undo()->index(), steps + 2);
    const auto& strip = holds(0).back();
    EXPECT_GT((strip[1] - strip[0]).maxCoeff(), 2 * HoldTool::kDefaultMargin + 1e-4) << "the stroke's extent";
    EXPECT_GT(w->viewport()->authoringMeshCount(), 1u) << "the held boxes are drawn";
    test::saveShot("hold_tool_boxes");
    // undo restores, redo takes it again
    undo()->undo();
    EXPECT_EQ(holds(0).size(), before.size() + 1);
    undo()->redo();
    EXPECT_EQ(holds(0).size(), before.size() + 2);
    // Release holds: one step, every box of the body
    if (QWindow* win = w->viewport()->canvasWindow())
        QTest::keyClick(win, Qt::Key_Escape);
    else
        QTest::keyClick(w->viewport()->canvasWidget(), Qt::Key_Escape);
    EXPECT_TRUE(test::waitFor([&] { return !tool->action()->isChecked(); }, 2000)) << "Esc ends the tool";
    ASSERT_TRUE(test::waitFor([&] { return w->findChild<QPushButton*>("releaseHoldsButton") != nullptr; }, 5000));
    QTest::mouseClick(w->findChild<QPushButton*>("releaseHoldsButton"), Qt::LeftButton);
    EXPECT_TRUE(holds(0).empty());
    EXPECT_EQ(undo()->index(), steps + 3);
    undo()->undo();
    EXPECT_EQ(holds(0).size(), before.size() + 2);
}

TEST_F(HoldToolFixture, ABadMarginOrASurroundingIsRefusedAndChangesNothing) {
    openSample("rectum");
    const QPoint onFat = over("fat");
    ASSERT_GE(onFat.x(), 0);
    holdOn(onFat);
    // the margin field: a bad value is refused and shows the rule; a good one is taken
    auto* margin = w->findChild<QLineEdit*>("hold_margin_mm");
    ASSERT_NE(margin, nullptr);
    margin->setFocus();
    margin->selectAll();
    QTest::keyClicks(margin, "500");
    QTest::keyClick(margin, Qt::Key_Return);
    EXPECT_THAT(w->findChild<QLabel*>("propertyError")->text().toStdString(),
                HasSubstr("hold margin: must be in (0, 100] mm"));
    EXPECT_DOUBLE_EQ(tool->margin(), HoldTool::kDefaultMargin);
    EXPECT_EQ(margin->text(), "5") << "the field shows the margin in use again";
    margin->selectAll();
    QTest::keyClicks(margin, "8");
    QTest::keyClick(margin, Qt::Key_Return);
    EXPECT_DOUBLE_EQ(tool->margin(), 0.008);
    // a click on the fat holds it with the new margin; the fascia over it holds the fat too
    ASSERT_TRUE(tool->action()->isChecked());
    const auto fatBefore = holds(0);
    const int steps = undo()->index();
    viewportClick(onFat);
    ASSERT_EQ(holds(0).size(), fatBefore.size() + 1);
    EXPECT_NEAR(holds(0).back()[1].y() - holds(0).back()[0].y(), 0.016, 1e-9);
    EXPECT_TRUE(tool->hold("fascia", {sim::Vec3(0, 0.01, 0)}).isEmpty());
    ASSERT_EQ(holds(0).size(), fatBefore.size() + 2) << "the fascia's body, the fat, is held";
    undo()->undo();
    // a click on a surrounding: refused, nothing changes
    const QPoint onWall = over("pelvic_wall");
    ASSERT_GE(onWall.x(), 0) << "the pelvic wall is drawn";
    const std::string before = studio::projectJsonText(w->document()->project());
    viewportClick(onWall);
    EXPECT_EQ(studio::projectJsonText(w->document()->project()), before);
    EXPECT_EQ(undo()->index(), steps + 1);
    EXPECT_THAT(tool->hold("pelvic_wall", {sim::Vec3::Zero()}).toStdString(),
                HasSubstr("'pelvic_wall' is not a body (only bodies can be held)"));
    // the reader's rule: at most 64 boxes
    for (size_t k = holds(0).size(); k < studio::kMaxHoldBoxes; ++k)
        ASSERT_TRUE(tool->hold("fat", {sim::Vec3(0, 0.01, -0.004)}).isEmpty()) << k;
    const std::string full = studio::projectJsonText(w->document()->project());
    EXPECT_THAT(tool->hold("fat", {sim::Vec3(0, 0.01, -0.004)}).toStdString(), HasSubstr("bodies[0].fixed"));
    EXPECT_EQ(studio::projectJsonText(w->document()->project()), full);
}

} // namespace
