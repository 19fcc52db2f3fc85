// The "Laparoscope and task" dock [issue 57 item 1]: the case's laparoscope and the task shown to
// the trainee, typed into the dock's fields with the keyboard and mouse, each one undo step
// through the Document, checked by the scene reader's rules; a refused value names the field and
// the rule and the model is unchanged. "Set scope view from here" takes the viewport's camera.
#include "app/document.hpp"
#include "app/main_window.hpp"
#include "app/scope_task_panel.hpp"
#include "app/viewport.hpp"
#include "gui_test_support.hpp"
#include "project/project.hpp"
#include "sim/scene/scene.hpp"
#include "window_fixture.hpp"

#include <QCheckBox>
#include <QComboBox>
#include <QDockWidget>
#include <QLabel>
#include <QLineEdit>
#include <QListWidget>
#include <QPushButton>
#include <QUndoStack>
#include <QWindow>

#include <gtest/gtest.h>

namespace {

using namespace viscera;
using Panel = studio::ScopeTaskPanel;

struct ScopeTaskFixture : test::MainWindowFixture {
    Panel* panel = nullptr;
    ScopeTaskFixture() : MainWindowFixture("viscera-gui-scope-task") {}
    void SetUp() override {
        MainWindowFixture::SetUp();
        panel = w->findChild<Panel*>("scopeTaskPanel");
        ASSERT_NE(panel, nullptr);
        w->findChild<QDockWidget*>("scopeTaskDock")->raise();
    }
    /// Types `text` into a line edit as a user does: focus, select all, type, Enter.
    static void typeInto(QLineEdit* f, const QString& text) {
        f->setFocus();
        f->selectAll();
        QTest::keyClicks(f, text);
        QTest::keyClick(f, Qt::Key_Return);
        QCoreApplication::processEvents();
    }
    /// Pastes `text` (a control character cannot be typed) and presses Enter.
    static void pasteInto(QLineEdit* f, const QString& text) {
        f->setFocus();
        f->setText(text);
        QTest::keyClick(f, Qt::Key_Return);
        QCoreApplication::processEvents();
    }
    const sim::LaparoscopeDesc& scope() const { return *w->document()->project().scene.laparoscope; }
    QUndoStack* undo() { return w->document()->undoStack(); }
    QString error() const { return panel->errorLabel()->text(); }
};

/// A drag on the viewport's surface (the embedded window, or the GL widget): orbits the camera.
void hostDrag(studio::Viewport* v, QPoint from, QPoint to) {
    if (QWindow* win = v->canvasWindow()) {
        QTest::mousePress(win, Qt::LeftButton, Qt::NoModifier, from);
        for (int i = 1; i <= 10; ++i)
            QTest::mouseMove(win, from + (to - from) * i / 10);
        QTest::mouseRelease(win, Qt::LeftButton, Qt::NoModifier, to);
    } else {
        test::drag(v->canvasWidget(), from, to, 10);
    }
}

TEST_F(ScopeTaskFixture, ScopeValuesAreUndoableEditsAndRefusalsNameTheRule) {
    open("rectum");
    ASSERT_TRUE(w->document()->project().scene.laparoscope);
    QLineEdit* fov = panel->field("fov_deg");
    ASSERT_NE(fov, nullptr);
    EXPECT_EQ(fov->text(), "70") << "the project's field of view shown";
    EXPECT_TRUE(panel->presentBox()->isChecked());
    const int steps = undo()->count();

    typeInto(fov, "200");
    EXPECT_NE(error().indexOf("project.json: laparoscope.fov_deg: must be in [20, 120]"), -1) << error().toStdString();
    EXPECT_EQ(scope().fovDeg, 70.0) << "a refused value leaves the model unchanged";
    EXPECT_EQ(fov->text(), "70") << "the field shows the model again";
    EXPECT_EQ(undo()->count(), steps);

    typeInto(fov, "60");
    EXPECT_EQ(scope().fovDeg, 60.0);
    EXPECT_TRUE(error().isEmpty()) << error().toStdString();
    EXPECT_EQ(undo()->count(), steps + 1) << "one typed value, one undo step";

    QComboBox* optic = panel->opticBox();
    ASSERT_EQ(optic->currentIndex(), 1) << "the rectum's 30° optic";
    optic->setFocus();
    QTest::keyClick(optic, Qt::Key_Up);
    EXPECT_EQ(scope().opticDeg, 0.0);
    EXPECT_EQ(undo()->count(), steps + 2);

    // A shaft too short for the insertion, a tip beyond the port's reach: the rules named.
    typeInto(panel->field("shaft_length"), "0.1");
    EXPECT_NE(error().indexOf("laparoscope.port.shaft_length: must be at least"), -1) << error().toStdString();
    typeInto(panel->field("tip_x"), "0.5");
    EXPECT_NE(error().indexOf("laparoscope.tip: lies"), -1) << error().toStdString();
    EXPECT_EQ(scope().tip.x(), -0.075);
    // The rectum's assessment measures out_of_view_s: the scope cannot go.
    QTest::mouseClick(panel->presentBox(), Qt::LeftButton, Qt::NoModifier,
                      QPoint(8, panel->presentBox()->height() / 2));
    EXPECT_NE(error().indexOf("assessment.metrics.out_of_view_s: needs a laparoscope"), -1) << error().toStdString();
    EXPECT_TRUE(w->document()->project().scene.laparoscope);
    EXPECT_TRUE(panel->presentBox()->isChecked()) << "the box shows the model again";
    EXPECT_EQ(undo()->count(), steps + 2) << "nothing refused reaches the undo stack";

    undo()->undo();
    EXPECT_EQ(scope().opticDeg, 30.0);
    EXPECT_EQ(optic->currentIndex(), 1) << "the combo follows undo";
    undo()->undo();
    EXPECT_EQ(scope().fovDeg, 70.0);
    EXPECT_EQ(fov->text(), "70");
}

TEST_F(ScopeTaskFixture, SetScopeViewFromHereTakesTheViewportCamera) {
    open("rectum");
    studio::Viewport* v = w->viewport();
    ASSERT_NE(v, nullptr);
    const sim::LaparoscopeDesc before = scope();
    const Eigen::Vector3f eye = v->camera().position;
    const QPoint centre(v->width() / 2, v->height() / 2);
    hostDrag(v, centre, centre + QPoint(90, -40));
    ASSERT_GT((v->camera().position - eye).norm(), 1e-4f) << "the drag did not move the camera";
    const int steps = undo()->count();
    QTest::mouseClick(panel->setViewButton(), Qt::LeftButton);
    EXPECT_TRUE(error().isEmpty()) << error().toStdString();
    EXPECT_EQ(undo()->count(), steps + 1) << "one undo step";
    const render::Camera& c = v->camera();
    QString why;
    const std::optional<sim::Vec3> expected =
        studio::scopeTipFromView(before.port, c.position.cast<double>(), c.target.cast<double>(), why);
    ASSERT_TRUE(expected) << why.toStdString();
    EXPECT_LT((scope().tip - *expected).norm(), 1e-12);
    EXPECT_GT((scope().tip - before.tip).norm(), 1e-3) << "the scope's tip moved";
    // the rule: the shaft from the port towards where the camera looks, within the insertion
    const sim::Vec3 shaft = (scope().tip - before.port.position).normalized();
    const sim::Vec3 look = (c.target.cast<double>() - before.port.position).normalized();
    EXPECT_GT(shaft.dot(look), 1 - 1e-9);
    EXPECT_TRUE(sim::restTipError(scope().port, scope().tip).empty());
    EXPECT_NE(panel->field("tip_x")->text(), "-0.075") << "the fields follow";
    undo()->undo();
    EXPECT_EQ(scope().tip, before.tip) << "undo restores the start view";
}

TEST_F(ScopeTaskFixture, TaskTitleInstructionsAndStepsAreUndoableAndReachTheExportedScene) {
    const std::filesystem::path dir = open("rectum");
    const std::string title = w->document()->project().title;
    const int steps = undo()->count();
    pasteInto(panel->titleField(), "Mesorectal\x01 dissection");
    EXPECT_NE(error().indexOf("project.json: title: must be printable text: control character U+0001"), -1)
        << error().toStdString();
    EXPECT_EQ(w->document()->project().title, title);
    EXPECT_EQ(panel->titleField()->text().toStdString(), title) << "the field shows the model again";
    pasteInto(panel->instructionsField(), "Grasp\x1b[31m the fascia");
    EXPECT_NE(error().indexOf("instructions: must be printable text: control character U+001B"), -1)
        << error().toStdString();
    EXPECT_EQ(undo()->count(), steps);

    // Two steps added and typed, one undo step each; the second moved up.
    QListWidget* list = panel->stepsList();
    auto addStep = [&](const QString& text) {
        QTest::mouseClick(panel->addStepButton(), Qt::LeftButton);
        auto* editor = list->viewport()->findChild<QLineEdit*>();
        ASSERT_NE(editor, nullptr) << "Add opened the new step's editor";
        QTest::keyClicks(editor, text);
        QTest::keyClick(editor, Qt::Key_Return);
        // the delegate commits queued, and the list's itemChanged is queued after that
        for (int k = 0; k < 3; ++k)
            QCoreApplication::processEvents();
        QCoreApplication::sendPostedEvents(nullptr, QEvent::DeferredDelete);
    };
    addStep("Grasp and lift the fascia");
    EXPECT_EQ(w->document()->project().scene.steps, std::vector<std::string>{"Grasp and lift the fascia"});
    EXPECT_EQ(undo()->count(), steps + 1) << "a step added and typed: one undo step";
    addStep("Clip the vessel twice");
    EXPECT_EQ(undo()->count(), steps + 2);
    list->setCurrentRow(1);
    QTest::mouseClick(panel->stepUpButton(), Qt::LeftButton);
    const std::vector<std::string> ordered = {"Clip the vessel twice", "Grasp and lift the fascia"};
    EXPECT_EQ(w->document()->project().scene.steps, ordered);
    EXPECT_EQ(undo()->count(), steps + 3);
    ASSERT_EQ(list->count(), 2);
    EXPECT_EQ(list->item(0)->text(), "Clip the vessel twice");
    typeInto(panel->titleField(), "Mesorectal dissection");
    EXPECT_EQ(w->document()->project().title, "Mesorectal dissection");
    EXPECT_EQ(undo()->count(), steps + 4);
    typeInto(panel->field("fov_deg"), "60");
    test::saveShot("scope_task_panel");
    if (const char* shots = std::getenv("VISCERA_GUI_SHOTS"); shots && *shots)
        w->findChild<QDockWidget*>("scopeTaskDock")
            ->grab()
            .save(QString::fromStdString((std::filesystem::path(shots) / "scope_task_dock.png").string()));

    // Saved, loaded back, and built into the scene the player reads.
    w->document()->save();
    const studio::Project back = studio::loadProject(dir);
    EXPECT_EQ(back.scene.steps, ordered);
    EXPECT_EQ(back.title, "Mesorectal dissection");
    ASSERT_TRUE(back.scene.laparoscope);
    EXPECT_EQ(back.scene.laparoscope->fovDeg, 60.0);
    const studio::BuiltScene built = studio::buildScene(back);
    const sim::SceneDesc player = sim::parseScene(sim::formatScene(built.scene), "scene.json");
    EXPECT_EQ(player.steps, ordered);
    ASSERT_TRUE(player.laparoscope);
    EXPECT_EQ(player.laparoscope->fovDeg, 60.0);

    // Remove a step, then undo everything back to the project as opened.
    list->setCurrentRow(0);
    QTest::mouseClick(panel->removeStepButton(), Qt::LeftButton);
    EXPECT_EQ(w->document()->project().scene.steps, std::vector<std::string>{"Grasp and lift the fascia"});
    while (undo()->index() > steps)
        undo()->undo();
    EXPECT_TRUE(w->document()->project().scene.steps.empty());
    EXPECT_EQ(w->document()->project().title, title);
    EXPECT_EQ(list->count(), 0) << "the list follows undo";
}

} // namespace
