// The curve-based material editor driven by synthetic mouse and key events (label gui, Xvfb):
// insert, drag (one that tries to break monotonicity included), delete, snap, typed values,
// undo/redo restoring the model bit-exactly, the shape rule after every sequence of edits.
#include "app/document.hpp"
#include "app/material_panel.hpp"
#include "gui_test_support.hpp"

#include <QKeyEvent>
#include <QLabel>
#include <QLineEdit>

#include <gtest/gtest.h>

namespace {

using namespace viscera;
using studio::CurveEditor;
using test::click;
using test::drag;
using test::sendMouse;
using Points = std::vector<std::array<double, 2>>;

struct PanelFixture : ::testing::Test {
    test::Scratch scratch{"viscera-gui-curves"};
    studio::Document doc;
    std::unique_ptr<studio::MaterialPanel> panel;

    void SetUp() override {
        test::guiApp();
        doc.open(QString::fromStdString(test::copySample(scratch, "tissue-slab").string()));
        panel = std::make_unique<studio::MaterialPanel>(&doc);
        panel->resize(1400, 900);
        panel->show();
        ASSERT_TRUE(QTest::qWaitForWindowExposed(panel.get()));
        panel->setBody(0);
        ASSERT_EQ(panel->applyPreset("neo_hookean", 3000, 0.45), "");
        for (int k = 0; k < 3; ++k)
            panel->editor(k)->frameAll();
        QCoreApplication::processEvents();
    }
    const sim::Material& material() const { return doc.project().bodies[0].scene.material; }
    Points f() const { return material().fPrime->points; }
    Points h() const { return material().hPrime->points; }
    CurveEditor* fe() { return panel->editor(0); }
    CurveEditor* he() { return panel->editor(2); }
    QPointF at(CurveEditor* e, size_t i) {
        const auto& p = e->points()[i];
        return e->toWidget({p.x, p.y});
    }
    /// Every curve with the strictly increasing rule is strictly increasing (x always).
    void expectShapeRule() {
        const sim::Material& m = material();
        for (const auto* d : {&m.fPrime, &m.gPrime, &m.hPrime}) {
            if (!*d) continue;
            const Points& p = (*d)->points;
            for (size_t i = 1; i < p.size(); ++i) {
                EXPECT_LT(p[i - 1][0], p[i][0]) << "x at " << i;
                if (!(*d)->unconstrained) {
                    EXPECT_LT(p[i - 1][1], p[i][1]) << "y at " << i;
                }
            }
        }
    }
    size_t restIndex(const Points& p) {
        for (size_t i = 0; i < p.size(); ++i)
            if (p[i][0] == 1.0) return i;
        return p.size();
    }
    /// A point that is neither an end nor the rest point.
    size_t movable(const Points& p) {
        const size_t r = restIndex(p);
        for (size_t i = 1; i + 1 < p.size(); ++i)
            if (i != r && i + 1 != r && i - 1 != r) return i;
        return 1;
    }
};

TEST_F(PanelFixture, PresetHasARestPointAndZeroStressAtRest) {
    EXPECT_LT(restIndex(f()), f().size());
    EXPECT_LT(restIndex(h()), h().size());
    EXPECT_TRUE(panel->restLabel()->text().contains("(zero)")) << panel->restLabel()->text().toStdString();
    EXPECT_FALSE(panel->uniaxialPlot()->series().empty());
    EXPECT_FALSE(panel->shearPlot()->series().empty());
}

TEST_F(PanelFixture, ClickNearTheCurveInsertsOnePointOnIt) {
    const Points before = f();
    const size_t i = movable(before);
    const double x = 0.5 * (before[i][0] + before[i + 1][0]);
    const double y = fe()->curveValue(x);
    const int undo = doc.undoStack()->count();
    click(fe(), fe()->toWidget({x, y}) + QPointF(0, 2)); // 2 px off the curve: still near
    ASSERT_EQ(f().size(), before.size() + 1);
    EXPECT_EQ(doc.undoStack()->count(), undo + 1);
    EXPECT_NEAR(f()[i + 1][1], y, 1e-9 * std::abs(y) + 1e-9);
    EXPECT_EQ(fe()->selected(), static_cast<int>(i + 1));
    expectShapeRule();
    // far from the curve: no insert
    click(fe(), fe()->toWidget({x, y}) + QPointF(0, 60));
    EXPECT_EQ(f().size(), before.size() + 1);
    doc.undoStack()->undo();
    EXPECT_EQ(f(), before);
}

TEST_F(PanelFixture, FiftyEventDragIsOneUndoStepAndUndoRestoresBitExactly) {
    const Points before = f(), hBefore = h();
    const size_t i = movable(before);
    const int undo = doc.undoStack()->count();
    // far past the right neighbour and below the left one: the shape rule must hold throughout
    const QPointF from = at(fe(), i);
    const QPointF to = fe()->toWidget({before[i + 1][0] + 2.0, before[i - 1][1] - 5000.0});
    int violations = 0;
    sendMouse(fe(), QEvent::MouseButtonPress, from, Qt::LeftButton, Qt::LeftButton);
    for (int s = 1; s <= 50; ++s) {
        sendMouse(fe(), QEvent::MouseMove, from + (s / 50.0) * (to - from), Qt::NoButton, Qt::LeftButton);
        const Points p = f();
        for (size_t k = 1; k < p.size(); ++k)
            violations += !(p[k - 1][0] < p[k][0]) || !(p[k - 1][1] < p[k][1]);
    }
    sendMouse(fe(), QEvent::MouseButtonRelease, to, Qt::LeftButton, Qt::NoButton);
    EXPECT_EQ(violations, 0);
    EXPECT_EQ(doc.undoStack()->count(), undo + 1) << "one drag, one undo step";
    const Points after = f();
    EXPECT_NE(after, before);
    EXPECT_LT(after[i][0], before[i + 1][0]) << "the point never passes its neighbour";
    EXPECT_GT(after[i][1], before[i - 1][1]);
    // the rule is enforced during the drag: the point follows the mouse up to its neighbours
    // (clamped there), it is not merely left where a refused event found it
    EXPECT_NEAR(after[i][0], before[i + 1][0], 1e-5 * before[i + 1][0]);
    EXPECT_NEAR(after[i][1], before[i - 1][1], 1e-5 * std::abs(before[i - 1][1]) + 1e-9);
    expectShapeRule();
    doc.undoStack()->undo();
    EXPECT_EQ(f(), before) << "bit-exact";
    EXPECT_EQ(h(), hBefore);
    doc.undoStack()->redo();
    EXPECT_EQ(f(), after);
}

TEST_F(PanelFixture, TheRestPointIsPinned) {
    const Points before = f();
    const size_t r = restIndex(before);
    drag(fe(), at(fe(), r), at(fe(), r) + QPointF(30, -40), 10);
    EXPECT_EQ(f(), before);
    fe()->setSelected(static_cast<int>(r));
    QTest::keyClick(fe(), Qt::Key_Delete);
    EXPECT_EQ(f(), before);
    EXPECT_TRUE(panel->restLabel()->text().contains("(zero)"));
}

TEST_F(PanelFixture, DeleteRemovesTheSelectedPointButNotAnEnd) {
    const Points before = f();
    const size_t i = movable(before);
    click(fe(), at(fe(), i));
    ASSERT_EQ(fe()->selected(), static_cast<int>(i));
    QTest::keyClick(fe(), Qt::Key_Delete);
    ASSERT_EQ(f().size(), before.size() - 1);
    expectShapeRule();
    click(fe(), at(fe(), 0));
    ASSERT_EQ(fe()->selected(), 0);
    QTest::keyClick(fe(), Qt::Key_Delete);
    EXPECT_EQ(f().size(), before.size() - 1) << "an end point stays";
    doc.undoStack()->undo();
    EXPECT_EQ(f(), before);
}

TEST_F(PanelFixture, CtrlSnapsADragToTheGrid) {
    const Points before = f();
    const size_t i = movable(before);
    const double sx = fe()->gridStepX(), sy = fe()->gridStepY();
    // a grid node strictly between the neighbours, if any; else the test cannot place one
    const double gx = std::ceil((before[i - 1][0] + 1e-9) / sx) * sx;
    const double gy = std::ceil((before[i - 1][1] + 1e-9) / sy) * sy;
    ASSERT_LT(gx, before[i + 1][0]) << "grid too coarse for this point";
    ASSERT_LT(gy, before[i + 1][1]);
    const QPointF target = fe()->toWidget({gx + 0.2 * sx, gy + 0.2 * sy});
    drag(fe(), at(fe(), i), target, 12, Qt::LeftButton, Qt::ControlModifier);
    const Points p = f();
    EXPECT_NEAR(p[i][0], gx, 1e-9 * sx);
    EXPECT_NEAR(p[i][1], gy, 1e-9 * sy);
    expectShapeRule();
}

TEST_F(PanelFixture, TypedValueIsOneStepAndAViolationIsRefusedWithTheRule) {
    const Points before = f();
    const size_t i = movable(before);
    click(fe(), at(fe(), i));
    const double y = 0.5 * (before[i][1] + before[i + 1][1]);
    panel->pointY()->setText(QString::number(y, 'g', 17));
    EXPECT_EQ(panel->applyTypedPoint(), "");
    EXPECT_EQ(f()[i][1], y);
    // above the right neighbour: refused, naming the point and the rule
    panel->pointY()->setText(QString::number(before[i + 1][1] + 1000, 'g', 17));
    const QString why = panel->applyTypedPoint();
    EXPECT_TRUE(why.contains("strictly")) << why.toStdString();
    EXPECT_TRUE(why.contains(QString("point %1").arg(i))) << why.toStdString();
    EXPECT_EQ(f()[i][1], y);
    panel->pointY()->setText("abc");
    EXPECT_TRUE(panel->applyTypedPoint().contains("not a finite number"));
    doc.undoStack()->undo();
    EXPECT_EQ(f(), before);
}

TEST_F(PanelFixture, WheelZoomsMiddleDragPansHomeFrames) {
    const QRectF v0 = fe()->view();
    QWheelEvent wheel(QPointF(300, 200), fe()->mapToGlobal(QPointF(300, 200)), QPoint(), QPoint(0, 240), Qt::NoButton,
                      Qt::NoModifier, Qt::NoScrollPhase, false);
    QApplication::sendEvent(fe(), &wheel);
    EXPECT_LT(fe()->view().width(), v0.width());
    const QRectF v1 = fe()->view();
    drag(fe(), QPointF(300, 200), QPointF(360, 200), 5, Qt::MiddleButton);
    EXPECT_LT(fe()->view().left(), v1.left());
    EXPECT_DOUBLE_EQ(fe()->view().width(), v1.width());
    QTest::keyClick(fe(), Qt::Key_Home);
    EXPECT_DOUBLE_EQ(fe()->view().width(), v0.width());
}

TEST_F(PanelFixture, ManyMixedEditsKeepEveryCurveStrictlyIncreasing) {
    std::srand(7);
    for (int round = 0; round < 30; ++round) {
        CurveEditor* e = round % 2 ? fe() : he();
        const auto& pts = e->points();
        const size_t i = 1 + static_cast<size_t>(std::rand()) % (pts.size() - 2);
        const QPointF from = e->toWidget({pts[i].x, pts[i].y});
        const QPointF to = from + QPointF(std::rand() % 400 - 200, std::rand() % 400 - 200);
        drag(e, from, to, 8, Qt::LeftButton, round % 3 ? Qt::NoModifier : Qt::ControlModifier);
        if (round % 5 == 4) {
            e->setSelected(static_cast<int>(i));
            QTest::keyClick(e, Qt::Key_Delete);
        }
        expectShapeRule();
    }
    while (doc.undoStack()->canUndo())
        doc.undoStack()->undo();
    EXPECT_EQ(material().model, sim::MaterialModel::StableNeoHookean) << "undo all restores the loaded material";
}

} // namespace
