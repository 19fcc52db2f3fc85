// The "Assessment" dock [issue 41]: the case's limits and expert levels typed into the table's
// cells with the keyboard, each one undo step through the Document, checked by the scene
// reader's rules; a refused value names the field and the rule and the model is unchanged.
#include "app/assessment_panel.hpp"
#include "app/document.hpp"
#include "app/main_window.hpp"
#include "gui_test_support.hpp"
#include "project/project.hpp"
#include "sim/util/atomic_file.hpp"
#include "window_fixture.hpp"

#include <QApplication>
#include <QDockWidget>
#include <QLabel>
#include <QLineEdit>
#include <QTableWidget>
#include <QUndoStack>

#include <gtest/gtest.h>

namespace {

using namespace viscera;
using Panel = studio::AssessmentPanel;

struct AssessmentPanelFixture : test::MainWindowFixture {
    Panel* panel = nullptr;
    AssessmentPanelFixture() : MainWindowFixture("viscera-gui-assessment") {}
    void SetUp() override {
        MainWindowFixture::SetUp();
        panel = w->assessmentPanel();
        ASSERT_NE(panel, nullptr);
        w->findChild<QDockWidget*>("assessmentDock")->raise();
    }
    int row(const std::string& metric) const {
        for (int r = 0; r < panel->table()->rowCount(); ++r)
            if (panel->table()->item(r, Panel::Metric)->text().toStdString() == metric) return r;
        return -1;
    }
    /// Types `text` into a cell as a user does: select it, type (which opens the editor), Enter.
    void typeInto(int r, int c, const QString& text) {
        QTableWidget* t = panel->table();
        t->setFocus();
        t->setCurrentCell(r, c);
        QTest::keyClick(t, Qt::Key_F2);
        auto* editor = t->viewport()->findChild<QLineEdit*>();
        ASSERT_NE(editor, nullptr) << "F2 opened the cell's editor";
        QTest::keyClick(editor, Qt::Key_A, Qt::ControlModifier);
        if (text.isEmpty())
            QTest::keyClick(editor, Qt::Key_Delete);
        else
            QTest::keyClicks(editor, text);
        QTest::keyClick(editor, Qt::Key_Return);
        QCoreApplication::processEvents();
        QCoreApplication::sendPostedEvents(nullptr, QEvent::DeferredDelete); // the closed editor goes
    }
    const sim::MetricLevel* level(const std::string& m) const {
        const auto& a = w->document()->project().scene.assessment;
        return a ? a->level(m) : nullptr;
    }
};

TEST_F(AssessmentPanelFixture, TypedLimitsAndExpertLevelsAreUndoableEditsOfTheModel) {
    open("rectum");
    const int clips = row("clips_on_target");
    ASSERT_GE(clips, 0);
    EXPECT_EQ(panel->table()->item(clips, Panel::Limit)->text(), "2") << "the project's limit shown";
    EXPECT_NE(panel->targetsLabel()->text().indexOf("2 clip(s) within 6 mm"), -1)
        << panel->targetsLabel()->text().toStdString();
    QUndoStack* undo = w->document()->undoStack();
    const int steps = undo->count();
    typeInto(clips, Panel::Limit, "3");
    ASSERT_TRUE(level("clips_on_target"));
    EXPECT_EQ(*level("clips_on_target")->limit, 3.0);
    EXPECT_EQ(undo->count(), steps + 1) << "one typed cell, one undo step";

    // An expert level for a metric that had none: mean, then SD (the level needs both).
    const int jerk = row("jerk_rms_m_s3");
    typeInto(jerk, Panel::ExpertMean, "40");
    EXPECT_EQ(level("jerk_rms_m_s3"), nullptr) << "half a level is not written";
    EXPECT_NE(panel->errorLabel()->text().indexOf("needs both a mean and an SD"), -1);
    typeInto(jerk, Panel::ExpertSd, "5");
    ASSERT_TRUE(level("jerk_rms_m_s3") && level("jerk_rms_m_s3")->expert);
    EXPECT_EQ(level("jerk_rms_m_s3")->expert->sd, 5.0);
    EXPECT_TRUE(panel->errorLabel()->text().isEmpty());
    test::saveShot("assessment_panel");

    undo->undo();
    EXPECT_EQ(level("jerk_rms_m_s3"), nullptr);
    undo->undo();
    EXPECT_EQ(*level("clips_on_target")->limit, 2.0);
    EXPECT_EQ(panel->table()->item(clips, Panel::Limit)->text(), "2") << "the table follows undo";
}

TEST_F(AssessmentPanelFixture, ARefusedValueNamesTheRuleAndLeavesTheModelUnchanged) {
    open("rectum");
    const int path = row("path_length_m");
    QUndoStack* undo = w->document()->undoStack();
    const int steps = undo->count();
    typeInto(path, Panel::Limit, "short");
    EXPECT_NE(panel->errorLabel()->text().indexOf("'short' is not a number"), -1);
    EXPECT_EQ(panel->table()->item(path, Panel::Limit)->text(), "0.8") << "the model's value again";
    typeInto(path, Panel::ExpertSd, "-1");
    EXPECT_NE(panel->errorLabel()->text().indexOf("assessment.metrics.path_length_m.expert.sd"), -1)
        << panel->errorLabel()->text().toStdString();
    EXPECT_EQ(level("path_length_m")->expert->sd, 0.04);
    EXPECT_EQ(undo->count(), steps) << "nothing refused reaches the undo stack";
    // The force threshold field: the reader's range (0, 50].
    QLineEdit* f = panel->thresholdField();
    f->setFocus();
    f->selectAll();
    QTest::keyClicks(f, "80");
    QTest::keyClick(f, Qt::Key_Return);
    EXPECT_NE(panel->errorLabel()->text().indexOf("force_threshold_n"), -1)
        << panel->errorLabel()->text().toStdString();
    EXPECT_EQ(w->document()->project().scene.assessment->forceThresholdN, 1.5);
    // Clearing a limit removes it (the metric keeps its expert level).
    typeInto(path, Panel::Limit, "");
    EXPECT_FALSE(level("path_length_m")->limit);
    EXPECT_TRUE(level("path_length_m")->expert);
}

TEST_F(AssessmentPanelFixture, ALimitTheSceneCannotMeasureIsRefusedWhenTyped) {
    // issue 57 item 7: the dock refuses what export would refuse, when it is typed
    open("tissue-slab"); // no laparoscope
    ASSERT_FALSE(w->document()->project().scene.laparoscope);
    const int oov = row("out_of_view_s");
    ASSERT_GE(oov, 0);
    QUndoStack* undo = w->document()->undoStack();
    const int steps = undo->count();
    const std::string before = studio::projectJsonText(w->document()->project());
    typeInto(oov, Panel::Limit, "5");
    EXPECT_NE(panel->errorLabel()->text().indexOf("assessment.metrics.out_of_view_s: needs a laparoscope"), -1)
        << panel->errorLabel()->text().toStdString();
    EXPECT_EQ(level("out_of_view_s"), nullptr);
    EXPECT_EQ(undo->count(), steps) << "the refused limit is not an undo step";
    EXPECT_EQ(studio::projectJsonText(w->document()->project()), before) << "the model unchanged";
    EXPECT_TRUE(panel->table()->item(oov, Panel::Limit)->text().isEmpty()) << "the cell shows the model again";
}

} // namespace

namespace {

// Expert levels derived by `viscera-results expert-levels` are imported into the case: one undo
// step, limits kept; a file for another case, or with a metric the player does not measure, is
// refused naming the file, the field and the rule.
TEST_F(AssessmentPanelFixture, ExpertLevelsFromExpertSessionsAreImportedAsOneUndoStep) {
    const std::filesystem::path dir = open("rectum");
    const std::filesystem::path levels = dir / "levels.json";
    writeFileAtomic(levels, R"({"case_id": "rectum", "experts": ["e1", "e2"], "sessions": 6,
      "metrics": {"completion_time_s": {"expert": {"mean": 4.9, "sd": 0.4}, "n": 6},
                  "jerk_rms_m_s3": {"expert": {"mean": 38, "sd": 6}, "n": 6}}})");
    QUndoStack* undo = w->document()->undoStack();
    const int steps = undo->count();
    ASSERT_EQ(panel->importExpertLevels(QString::fromStdString(levels.string())), "");
    EXPECT_EQ(undo->count(), steps + 1);
    EXPECT_EQ(level("completion_time_s")->expert->mean, 4.9);
    EXPECT_EQ(*level("completion_time_s")->limit, 9.0) << "the limit is kept";
    EXPECT_EQ(level("jerk_rms_m_s3")->expert->sd, 6.0);
    EXPECT_EQ(panel->table()->item(row("jerk_rms_m_s3"), Panel::ExpertMean)->text(), "38");
    undo->undo();
    EXPECT_EQ(level("completion_time_s")->expert->mean, 5.2);
    EXPECT_EQ(level("jerk_rms_m_s3"), nullptr);

    writeFileAtomic(levels, R"({"case_id": "liver", "metrics": {}})");
    EXPECT_NE(panel->importExpertLevels(QString::fromStdString(levels.string()))
                  .indexOf("case_id: 'liver' is not this project's case ('rectum')"),
              -1);
    writeFileAtomic(levels, R"({"metrics": {"jerk_rms_m_s3": {"expert": {"mean": 1, "sd": 0}, "n": 2}}})");
    EXPECT_NE(panel->importExpertLevels(QString::fromStdString(levels.string()))
                  .indexOf("case_id: required field is missing"),
              -1)
        << "a file that does not say its case is refused";
    writeFileAtomic(levels, R"({"case_id": "rectum", "metrics": {}})");
    EXPECT_NE(
        panel->importExpertLevels(QString::fromStdString(levels.string())).indexOf("metrics: has no expert level"), -1);
    writeFileAtomic(levels, R"({"case_id": "rectum", "metrics": {"speed": {"expert": {"mean": 1, "sd": 0}, "n": 2}}})");
    const QString why = panel->importExpertLevels(QString::fromStdString(levels.string()));
    EXPECT_NE(why.indexOf("levels.json: metrics.speed: is not a metric the player measures"), -1) << why.toStdString();
    EXPECT_EQ(undo->count(), steps + 1) << "nothing refused reaches the undo stack";
}

} // namespace
