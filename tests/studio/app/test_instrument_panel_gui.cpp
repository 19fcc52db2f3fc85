// The "Instruments" dock [issue 57 item 1]: instruments added, edited and removed with synthetic
// clicks and keys, each one undo step through the Document, checked by the scene reader's rules;
// a refused value names the field and the rule and leaves the model unchanged; the new
// instrument's track is a file of the project, written on save; a saved project with a new
// instrument loads back and exports.
#include "app/document.hpp"
#include "app/instrument_panel.hpp"
#include "app/main_window.hpp"
#include "gui_test_support.hpp"
#include "project/project.hpp"
#include "sim/util/atomic_file.hpp"
#include "window_fixture.hpp"

#include <QComboBox>
#include <QDockWidget>
#include <QLabel>
#include <QLineEdit>
#include <QListWidget>
#include <QPushButton>
#include <QTreeWidgetItemIterator>
#include <QUndoStack>

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>

namespace {

using namespace viscera;
namespace fs = std::filesystem;
using Kind = sim::InstrumentDesc::Kind;

struct InstrumentPanelFixture : test::MainWindowFixture {
    studio::InstrumentPanel* panel = nullptr;
    InstrumentPanelFixture() : MainWindowFixture("viscera-gui-instruments") {}
    void SetUp() override {
        MainWindowFixture::SetUp();
        panel = w->findChild<studio::InstrumentPanel*>("instrumentPanel");
        ASSERT_NE(panel, nullptr);
        w->findChild<QDockWidget*>("instrumentDock")->raise();
    }
    const std::vector<sim::InstrumentDesc>& instruments() const {
        static const std::vector<sim::InstrumentDesc> none;
        const auto& i = w->document()->project().scene.interaction;
        return i ? i->instruments : none;
    }
    /// Chooses the kind Add makes with the keyboard (Home, then Down) and clicks Add.
    void addWithClicks(int kindRow) {
        QComboBox* kind = panel->addKindBox();
        kind->setFocus();
        QTest::keyClick(kind, Qt::Key_Home);
        for (int i = 0; i < kindRow; ++i)
            QTest::keyClick(kind, Qt::Key_Down);
        QTest::mouseClick(panel->addButton(), Qt::LeftButton);
    }
    /// Types `text` into a field as a user does: focus, select all, type, Return.
    void typeInto(const QString& key, const QString& text) {
        QLineEdit* f = panel->field(key);
        ASSERT_NE(f, nullptr) << key.toStdString();
        f->setFocus();
        f->selectAll();
        if (text.isEmpty())
            QTest::keyClick(f, Qt::Key_Delete);
        else
            QTest::keyClicks(f, text);
        QTest::keyClick(f, Qt::Key_Return);
        QCoreApplication::processEvents();
    }
    std::string error() const { return panel->errorLabel()->text().toStdString(); }
};

TEST_F(InstrumentPanelFixture, AddEditAndRemoveAClipApplierAreUndoableEditsOfTheModel) {
    const fs::path dir = open("rectum");
    ASSERT_EQ(instruments().size(), 3u);
    EXPECT_EQ(panel->list()->count(), 3);
    EXPECT_EQ(panel->list()->item(0)->text().toStdString(), "grasper — grasper — left");
    QUndoStack* undo = w->document()->undoStack();
    const int steps = undo->count();

    addWithClicks(2); // clip applier
    EXPECT_EQ(error(), "");
    ASSERT_EQ(instruments().size(), 4u);
    EXPECT_EQ(undo->count(), steps + 1) << "one click, one undo step";
    const sim::InstrumentDesc added = instruments().back();
    EXPECT_EQ(added.name, "clip_applier");
    EXPECT_EQ(added.kind, Kind::ClipApplier);
    EXPECT_EQ(added.target, "vessel") << "the body the other clip applier clips";
    EXPECT_EQ(added.device.hand, "right");
    EXPECT_TRUE(added.port.declared);
    EXPECT_EQ(added.trackPath, "tools/clip_applier.track");
    ASSERT_EQ(w->document()->project().trackFiles.size(), 4u);
    EXPECT_EQ(w->document()->project().trackFiles.back(), dir / "tools/clip_applier.track");
    const sim::InstrumentTrack track = sim::InstrumentTrack::parse(added.trackText, "added");
    ASSERT_EQ(track.keys().size(), 1u) << "a resting one-key track";
    EXPECT_TRUE(sim::restTipError(added.port, track.keys()[0].position).empty());
    EXPECT_EQ(panel->list()->count(), 4);
    EXPECT_EQ(panel->selected(), 3) << "the new instrument is shown";
    EXPECT_EQ(panel->targetBox()->currentText(), "vessel");
    EXPECT_TRUE(panel->targetBox()->isVisibleTo(panel)) << "a clip applier's own field";
    EXPECT_FALSE(panel->field("temperature_c")->isVisibleTo(panel)) << "a hook's field is hidden";

    // Saving writes the new track (atomically) and leaves the unchanged ones alone.
    const fs::path grasperTrack = dir / "tools/grasper.track";
    const auto old = fs::last_write_time(grasperTrack) - std::chrono::hours(1);
    fs::last_write_time(grasperTrack, old);
    fs::remove(dir / "tools/clip_applier.track"); // written on add; save writes what is missing or changed
    ASSERT_TRUE(w->saveProject());
    EXPECT_EQ(readFile(dir / "tools/clip_applier.track"), added.trackText);
    EXPECT_EQ(fs::last_write_time(grasperTrack), old) << "an unchanged track is not rewritten";
    EXPECT_NE(readFile(dir / "project.json").find("\"tools/clip_applier.track\""), std::string::npos);

    // A typed value: one undo step.
    const double angle = added.port.maxAngleDeg;
    typeInto("max_angle_deg", "45");
    EXPECT_EQ(error(), "");
    EXPECT_EQ(instruments()[3].port.maxAngleDeg, 45.0);
    EXPECT_EQ(undo->count(), steps + 2);
    // Refused values name the field and the rule; the model and the undo stack are unchanged.
    typeInto("max_angle_deg", "200");
    EXPECT_NE(error().find("project.json: interaction.instruments[3].port.max_angle_deg: "), std::string::npos)
        << error();
    EXPECT_EQ(instruments()[3].port.maxAngleDeg, 45.0);
    EXPECT_EQ(panel->field("max_angle_deg")->text(), "45") << "the model's value again";
    typeInto("radius", "-1");
    EXPECT_NE(error().find("interaction.instruments[3].radius: "), std::string::npos) << error();
    EXPECT_EQ(instruments()[3].radius, added.radius);
    typeInto("port_z", "2"); // the rest tip then lies far below the port: World::assemble's rule
    EXPECT_NE(error().find("interaction.instruments[3].port: the track's first tip lies"), std::string::npos)
        << error();
    EXPECT_EQ(instruments()[3].port.position, added.port.position);
    typeInto("jaw_length", "wide");
    EXPECT_NE(error().find("'wide' is not a finite number"), std::string::npos) << error();
    EXPECT_EQ(undo->count(), steps + 2) << "nothing refused reaches the undo stack";
    test::saveShot("instrument_panel_refused");
    undo->undo();
    EXPECT_EQ(instruments()[3].port.maxAngleDeg, angle);
    EXPECT_EQ(panel->field("max_angle_deg")->text().toDouble(), angle) << "the field follows undo";

    // Remove: one undo step; undo brings it back with its track.
    ASSERT_EQ(panel->selected(), 3);
    QTest::mouseClick(panel->removeButton(), Qt::LeftButton);
    EXPECT_EQ(error(), "");
    ASSERT_EQ(instruments().size(), 3u);
    EXPECT_EQ(w->document()->project().trackFiles.size(), 3u);
    EXPECT_EQ(undo->count(), steps + 2);
    EXPECT_EQ(panel->list()->count(), 3);
    undo->undo();
    ASSERT_EQ(instruments().size(), 4u);
    EXPECT_EQ(instruments()[3].name, "clip_applier");
    EXPECT_EQ(instruments()[3].trackText, added.trackText);
    EXPECT_EQ(w->document()->project().trackFiles.back(), dir / "tools/clip_applier.track");
    undo->undo(); // the add
    EXPECT_EQ(instruments().size(), 3u);
    EXPECT_EQ(w->document()->project().trackFiles.size(), 3u);
}

TEST_F(InstrumentPanelFixture, MasterFieldsAndChoicesAreUndoableAndTheClipTargetIsABody) {
    open("rectum");
    QUndoStack* undo = w->document()->undoStack();
    panel->list()->setCurrentRow(1); // the hook
    ASSERT_EQ(panel->selected(), 1);
    EXPECT_TRUE(panel->field("temperature_c")->isVisibleTo(panel));
    EXPECT_EQ(panel->field("temperature_c")->text(), "170");
    const int steps = undo->count();
    typeInto("temperature_c", "500");
    EXPECT_NE(error().find("interaction.instruments[1].temperature_c: "), std::string::npos) << error();
    typeInto("temperature_c", "200");
    EXPECT_EQ(instruments()[1].temperatureC, 200.0);
    typeInto("damage_force_n", "4");
    ASSERT_TRUE(instruments()[1].device.damageForceN);
    EXPECT_EQ(*instruments()[1].device.damageForceN, 4.0);
    typeInto("damage_force_n", ""); // empty: none (the assessment's threshold)
    EXPECT_FALSE(instruments()[1].device.damageForceN);
    typeInto("max_force_n", "80");
    EXPECT_NE(error().find("interaction.instruments[1].device.max_force_n: "), std::string::npos) << error();
    // the hand and the port mode: chosen with the keyboard in their combos
    QComboBox* hand = panel->handBox();
    hand->setFocus();
    QTest::keyClick(hand, Qt::Key_Home); // left
    EXPECT_EQ(instruments()[1].device.hand, "left");
    QComboBox* mode = panel->modeBox();
    mode->setFocus();
    QTest::keyClick(mode, Qt::Key_Home); // laparoscopic
    EXPECT_EQ(instruments()[1].port.mode, sim::PortMode::Laparoscopic);
    EXPECT_EQ(undo->count(), steps + 5);
    EXPECT_EQ(panel->list()->item(1)->text().toStdString(), "hook — energy hook — left");
    // the clip applier's target: only a body of the scene (the reader's names check)
    panel->list()->setCurrentRow(2);
    QStringList bodies;
    for (int i = 0; i < panel->targetBox()->count(); ++i)
        bodies << panel->targetBox()->itemText(i);
    EXPECT_EQ(bodies, QStringList({"fat", "vessel"}));
    QComboBox* target = panel->targetBox();
    target->setFocus();
    QTest::keyClick(target, Qt::Key_Home); // fat
    EXPECT_EQ(instruments()[2].target, "fat");
    EXPECT_EQ(w->document()->editInstrument("x", 2,
                                            [&] {
                                                sim::InstrumentDesc in = instruments()[2];
                                                in.target = "fascia";
                                                return in;
                                            }()),
              QString::fromStdString((w->document()->project().dir / "project.json").string()) +
                  ": interaction.instruments[2].target: 'fascia' is not a body of the scene");
    EXPECT_EQ(undo->count(), steps + 6) << "the refused target is not a step";
    for (int i = 0; i < 6; ++i)
        undo->undo();
    EXPECT_EQ(instruments()[1].temperatureC, 170.0);
    EXPECT_EQ(instruments()[1].device.hand, "right");
    EXPECT_EQ(instruments()[1].port.mode, sim::PortMode::Robotic);
    EXPECT_EQ(instruments()[2].target, "vessel");
}

TEST_F(InstrumentPanelFixture, AHookInAProjectWithoutInstrumentsBringsTheInteractionAndATissue) {
    open("tissue-slab");
    EXPECT_FALSE(w->document()->project().scene.interaction);
    EXPECT_EQ(panel->list()->count(), 0);
    EXPECT_FALSE(panel->removeButton()->isEnabled());
    QUndoStack* undo = w->document()->undoStack();
    const int steps = undo->count();
    addWithClicks(1); // energy hook
    EXPECT_EQ(error(), "");
    ASSERT_TRUE(w->document()->project().scene.interaction);
    const sim::InteractionDesc& d = *w->document()->project().scene.interaction;
    ASSERT_EQ(d.instruments.size(), 1u);
    EXPECT_EQ(d.instruments[0].name, "energy_hook");
    ASSERT_EQ(d.tissues.size(), 1u) << "the reader's rule: a hook needs a tissue it can cut";
    EXPECT_EQ(d.tissues[0].layer, "slab");
    // the rest tip lies 2 cm above the slab (a box 0.08 × 0.04 × 0.03 m from the origin), the port above it
    const sim::InstrumentTrack track = sim::InstrumentTrack::parse(d.instruments[0].trackText, "hook");
    EXPECT_NEAR(track.keys()[0].position.z(), 0.03 + 0.02, 1e-9);
    EXPECT_NEAR(track.keys()[0].position.x(), 0.04, 1e-9);
    EXPECT_GT(d.instruments[0].port.position.z(), track.keys()[0].position.z());
    addWithClicks(1);
    ASSERT_EQ(instruments().size(), 2u);
    EXPECT_EQ(instruments()[1].name, "energy_hook_2");
    EXPECT_EQ(undo->count(), steps + 2);
    QTest::mouseClick(panel->removeButton(), Qt::LeftButton);
    panel->list()->setCurrentRow(0);
    QTest::mouseClick(panel->removeButton(), Qt::LeftButton);
    EXPECT_EQ(error(), "");
    EXPECT_FALSE(w->document()->project().scene.interaction) << "the last one takes the block with it";
    EXPECT_TRUE(w->document()->project().trackFiles.empty());
    EXPECT_EQ(studio::Document::check(w->document()->project()), "") << "the model passes the rules of load";
    undo->undo();
    ASSERT_EQ(instruments().size(), 1u);
    EXPECT_EQ(w->document()->project().scene.interaction->tissues.size(), 1u);
}

TEST_F(InstrumentPanelFixture, ScissorsAndANeedleDriverAreAddedEditedAndRemovedAsUndoSteps) {
    open("tissue-slab");
    QUndoStack* undo = w->document()->undoStack();
    const int steps = undo->index();
    addWithClicks(3); // scissors
    EXPECT_EQ(error(), "");
    ASSERT_EQ(instruments().size(), 1u);
    const sim::InstrumentDesc& sc = instruments()[0];
    EXPECT_EQ(sc.kind, Kind::Scissors);
    EXPECT_EQ(sc.name, "scissors");
    EXPECT_EQ(sc.device.hand, "right");
    EXPECT_DOUBLE_EQ(sc.jawLength, 0.014) << "long slim blades";
    ASSERT_EQ(w->document()->project().scene.interaction->tissues.size(), 1u)
        << "the reader's rule: scissors cut a tissue";
    EXPECT_EQ(undo->index(), steps + 1);
    addWithClicks(4); // needle driver
    ASSERT_EQ(instruments().size(), 2u);
    EXPECT_EQ(instruments()[1].kind, Kind::NeedleDriver);
    EXPECT_DOUBLE_EQ(instruments()[1].jawLength, 0.009) << "short strong jaws";
    EXPECT_EQ(panel->list()->item(1)->text().contains("needle driver"), true)
        << panel->list()->item(1)->text().toStdString();
    EXPECT_EQ(undo->index(), steps + 2);
    // the tree names the kinds
    bool treeSaysScissors = false;
    QStringList rows;
    test::waitFor(
        [&] { // the tree refreshes on its own time
            rows.clear();
            for (QTreeWidgetItemIterator it(w->tree()); *it; ++it) {
                rows << (*it)->text(0) + " | " + (*it)->text(1);
                treeSaysScissors =
                    treeSaysScissors || ((*it)->text(0) == "scissors" && (*it)->text(1).startsWith("scissors, right"));
            }
            return treeSaysScissors;
        },
        3000);
    EXPECT_TRUE(treeSaysScissors) << rows.join("\n").toStdString();
    // a typed jaw length: one step; a refused one names the rule and changes nothing
    panel->list()->setCurrentRow(0);
    typeInto("jaw_length", "0.018");
    EXPECT_EQ(error(), "");
    EXPECT_DOUBLE_EQ(instruments()[0].jawLength, 0.018);
    EXPECT_EQ(undo->index(), steps + 3);
    typeInto("jaw_length", "0.5");
    EXPECT_NE(error().find("jaw_length"), std::string::npos) << error();
    EXPECT_DOUBLE_EQ(instruments()[0].jawLength, 0.018);
    EXPECT_EQ(undo->index(), steps + 3);
    EXPECT_EQ(studio::Document::check(w->document()->project()), "") << "the model passes the rules of load";
    undo->undo();
    undo->undo();
    undo->undo();
    EXPECT_FALSE(w->document()->project().scene.interaction) << "undo restores the project as it was";
}

} // namespace

// A project saved with an instrument added in the studio loads back with the project reader and
// exports (the world assembled with the instrument: its rest tip within its port's reach).
TEST(InstrumentsSaved, AProjectWithAnAddedInstrumentLoadsBackAndExports) {
    test::guiApp();
    test::Scratch scratch("viscera-instruments-export");
    const fs::path dir = test::copySample(scratch, "tissue-slab");
    studio::Document doc;
    doc.open(QString::fromStdString(dir.string()));
    ASSERT_EQ(doc.addInstrument("add", Kind::Grasper, "left"), "");
    ASSERT_EQ(doc.addInstrument("add", Kind::ClipApplier, "right"), "");
    doc.save();
    const studio::Project back = studio::loadProject(dir);
    ASSERT_TRUE(back.scene.interaction);
    ASSERT_EQ(back.scene.interaction->instruments.size(), 2u);
    EXPECT_EQ(back.scene.interaction->instruments[1].target, "slab");
    EXPECT_EQ(back.scene.interaction->instruments[0].trackText,
              doc.project().scene.interaction->instruments[0].trackText);
    EXPECT_EQ(studio::projectJsonText(back), studio::projectJsonText(doc.project()));
    const studio::ExportResult r = studio::exportCase(back, scratch.dir / "slab.vcase");
    EXPECT_TRUE(fs::exists(r.casePath));
    for (const char* f : {"collision", "clip"})
        EXPECT_NE(std::find(r.features.begin(), r.features.end(), f), r.features.end()) << f;
}
