// The curve-based material editor driven by synthetic mouse and key events (label gui, Xvfb):
// insert, drag (one that tries to break monotonicity included), delete, snap, typed values,
// undo/redo restoring the model bit-exactly, the shape rule after every sequence of edits.
#include "app/document.hpp"
#include "app/material_panel.hpp"
#include "app/plot_widget.hpp"
#include "gui_test_support.hpp"

#include <QKeyEvent>
#include <QLabel>
#include <QLineEdit>
#include <QPushButton>

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
    // free edits: the point follows the mouse and pushes the neighbours it passes along; only the
    // pinned rest point (x = 1) stops it
    const size_t rest = restIndex(before);
    ASSERT_GT(rest, i);
    EXPECT_GT(after[i][0], before[i + 1][0]) << "the point passed its old neighbour";
    EXPECT_LT(after[i][0], 1.0) << "but not the rest point";
    EXPECT_NEAR(after[i][0], 1.0, 1e-4);
    EXPECT_NEAR(after[i][1], before[i - 1][1] - 5000.0, 1.0) << "the point is where the mouse is";
    EXPECT_LT(after[i][1], before[i - 1][1]) << "below its old left neighbour";
    EXPECT_LT(after[i - 1][1], after[i][1]) << "which was pushed down";
    EXPECT_EQ(after[rest], before[rest]) << "the rest point stays";
    for (size_t k = rest; k < before.size(); ++k)
        EXPECT_EQ(after[k], before[k]) << "nothing beyond the rest point moves";
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

namespace {

/// The uniaxial response plot's stress at the sample nearest stretch `lambda`.
double uniaxialAt(studio::MaterialPanel& panel, double lambda) {
    const auto& s = panel.uniaxialPlot()->series().at(0);
    size_t best = 0;
    for (size_t i = 0; i < s.x.size(); ++i)
        if (std::abs(s.x[i] - lambda) < std::abs(s.x[best] - lambda)) best = i;
    return s.y.at(best);
}

} // namespace

// Issue 39 item 2: a drag of the point beside the rest point, which used to be clamped between
// neighbours a few pixels apart, moves freely (its neighbours pushed along) and changes the
// material's response.
TEST_F(PanelFixture, ADragNearRestMovesFreelyAndChangesTheResponse) {
    const Points before = f();
    const size_t rest = restIndex(before);
    ASSERT_LT(rest + 2, before.size());
    const size_t i = rest + 1; // the first point in tension
    const double stressBefore = uniaxialAt(*panel, 1.2);
    const QPointF from = at(fe(), i);
    drag(fe(), from, from + QPointF(0, -60), 30); // 60 px up: far past its right neighbour's value
    const Points after = f();
    EXPECT_EQ(after[rest], before[rest]) << "the rest point stays";
    EXPECT_GT(after[i][1], before[i + 1][1]) << "the point passed its old neighbour's value";
    EXPECT_GT(after[i + 1][1], after[i][1]) << "which was pushed up";
    expectShapeRule();
    test::saveShot("curve_drag_near_rest");
    const double stressAfter = uniaxialAt(*panel, 1.2);
    EXPECT_GT(stressAfter, stressBefore * 1.02) << "the response at 20 % stretch changed";
    for (const auto& p : after) // a drag that left points out of sight frames the view at its end
        EXPECT_TRUE(fe()->view().contains(QPointF(p[0], p[1]))) << p[0] << ", " << p[1];
}

TEST_F(PanelFixture, ScaleSmoothAndResetAreOneUndoStepEachAndKeepTheShape) {
    const Points preset = f();
    const size_t rest = restIndex(preset);
    const int undo = doc.undoStack()->count();
    panel->findChild<QLineEdit*>("scaleFactor")->setText("2");
    fe()->setSelected(1); // makes f' the active curve
    panel->findChild<QPushButton*>("scaleCurve")->click();
    ASSERT_EQ(panel->statusLabel()->text(), "");
    const Points scaled = f();
    ASSERT_EQ(scaled.size(), preset.size());
    for (size_t k = 0; k < preset.size(); ++k)
        EXPECT_NEAR(scaled[k][1] - preset[rest][1], 2.0 * (preset[k][1] - preset[rest][1]),
                    1e-9 * std::abs(preset[k][1]) + 1e-9);
    EXPECT_EQ(scaled[rest], preset[rest]);
    expectShapeRule();
    // the editor framed itself: every point is in view
    for (const auto& p : scaled)
        EXPECT_TRUE(fe()->view().contains(QPointF(p[0], p[1]))) << p[0] << ", " << p[1];
    EXPECT_EQ(doc.undoStack()->count(), undo + 1);
    panel->findChild<QPushButton*>("smoothCurve")->click();
    ASSERT_EQ(panel->statusLabel()->text(), "");
    EXPECT_NE(f(), scaled);
    EXPECT_EQ(f()[rest], preset[rest]);
    expectShapeRule();
    EXPECT_EQ(doc.undoStack()->count(), undo + 2);
    panel->findChild<QPushButton*>("resetCurve")->click();
    ASSERT_EQ(panel->statusLabel()->text(), "");
    EXPECT_EQ(f(), preset) << "reset gives the preset's curve again";
    EXPECT_EQ(doc.undoStack()->count(), undo + 3);
    // a factor that would reverse the curve is refused with the rule
    panel->findChild<QLineEdit*>("scaleFactor")->setText("-1");
    panel->findChild<QPushButton*>("scaleCurve")->click();
    EXPECT_TRUE(panel->statusLabel()->text().contains("must be a positive number"))
        << panel->statusLabel()->text().toStdString();
    EXPECT_EQ(doc.undoStack()->count(), undo + 3);
    doc.undoStack()->undo();
    doc.undoStack()->undo();
    doc.undoStack()->undo();
    EXPECT_EQ(f(), preset);
}

// Issue 39 item 1: every typed edit is checked by the reader's rule for its value and refused
// with the file, the field and the rule; a refused edit leaves the model and the undo stack.
TEST_F(PanelFixture, TypedEditsAreCheckedByTheReadersRulesAndUndoExactly) {
    const int undo = doc.undoStack()->count();
    const std::string file = (doc.project().dir / "project.json").string();
    sim::XpbdSettings s = doc.project().scene.xpbd;
    s.substeps = 0;
    EXPECT_EQ(doc.editSolver("substeps", s).toStdString(), file + ": solver: substeps must be in [1, 1000]");
    s.substeps = 77;
    EXPECT_EQ(doc.editSolver("substeps", s), "");
    EXPECT_EQ(doc.project().scene.xpbd.substeps, 77);
    std::optional<studio::StiffnessPaintProject> paint = studio::StiffnessPaintProject{};
    sim::BrushStroke bad;
    bad.radius = 0; // the reader's rule: radius in [1e-6, 1e3] m
    paint->strokes.push_back(bad);
    const QString why = doc.editStiffnessPaint("paint", 0, -1, paint);
    EXPECT_TRUE(why.startsWith(QString::fromStdString(file + ": bodies[0].stiffness_paint.strokes: stroke 0: radius")))
        << why.toStdString();
    paint->strokes.front().radius = 0.01;
    EXPECT_EQ(doc.editStiffnessPaint("paint", 0, -1, paint), "");
    render::SamplePaintOp op;
    op.samples = 3; // not a sample class
    op.points.push_back(sim::Vec3::Zero());
    EXPECT_TRUE(doc.editLightSamples("samples", 0, {op}).contains("light_samples[0]"));
    EXPECT_EQ(doc.undoStack()->count(), undo + 2) << "two accepted edits, two steps";
    doc.undoStack()->undo();
    EXPECT_FALSE(doc.project().bodies[0].paint.has_value());
    doc.undoStack()->undo();
    EXPECT_NE(doc.project().scene.xpbd.substeps, 77);
}
