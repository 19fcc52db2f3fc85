// The "Surroundings" dock [issue 57 item 1]: the static anatomy around the tissue (scenery walls
// and floors) listed, added, removed and edited by typed values, each one undo step through the
// Document checked by the project reader's rule for "scenery"; refusals name the field and rule
// and leave the model unchanged; undo restores; the project tree lists them.
#include "app/document.hpp"
#include "app/main_window.hpp"
#include "app/surroundings_panel.hpp"
#include "app/texture_panel.hpp"
#include "gui_test_support.hpp"
#include "project/anatomy_shapes.hpp"
#include "project/sample_anatomy_files.hpp"
#include "window_fixture.hpp"

#include <QComboBox>
#include <QDialogButtonBox>
#include <QDockWidget>
#include <QFileDialog>
#include <QLabel>
#include <QLineEdit>
#include <QListView>
#include <QListWidget>
#include <QPlainTextEdit>
#include <QPushButton>
#include <QSettings>
#include <QTreeWidget>
#include <QUndoStack>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>

namespace {

using namespace viscera;
using ::testing::HasSubstr;

struct SurroundingsFixture : test::MainWindowFixture {
    studio::SurroundingsPanel* panel = nullptr;
    SurroundingsFixture() : MainWindowFixture("viscera-gui-surroundings") {}
    void SetUp() override {
        MainWindowFixture::SetUp();
        panel = w->findChild<studio::SurroundingsPanel*>("surroundingsPanel");
        ASSERT_NE(panel, nullptr);
        open("rectum");
        w->findChild<QDockWidget*>("surroundingsDock")->raise();
        QCoreApplication::processEvents();
    }
    const std::vector<studio::SceneryProject>& scenery() const { return w->document()->project().scenery; }
    QUndoStack* undo() { return w->document()->undoStack(); }
    /// Types `text` into the field `key` as a user does: select all, type, Enter.
    void type(const QString& key, const QString& text) {
        QLineEdit* e = panel->field(key);
        ASSERT_NE(e, nullptr);
        e->setFocus();
        QTest::keyClick(e, Qt::Key_A, Qt::ControlModifier);
        QTest::keyClicks(e, text);
        QTest::keyClick(e, Qt::Key_Return);
        QCoreApplication::processEvents();
    }
    int row(const std::string& name) const {
        for (size_t i = 0; i < scenery().size(); ++i)
            if (scenery()[i].name == name) return static_cast<int>(i);
        return -1;
    }
};

TEST_F(SurroundingsFixture, TypedValuesAreUndoableEditsAndRefusalsNameTheRule) {
    ASSERT_EQ(panel->list()->count(), static_cast<int>(scenery().size()));
    // the rectum's surroundings are imported anatomy: a wall added to edit
    QTest::mouseClick(panel->addWallButton(), Qt::LeftButton);
    const int wall = row("wall");
    ASSERT_GE(wall, 0);
    panel->list()->setCurrentRow(wall);
    const double radius0 = scenery()[size_t(wall)].radius;
    const bool inward0 = scenery()[size_t(wall)].inward;
    EXPECT_EQ(panel->field("radius_mm")->text(), QString::number(radius0 * 1e3));
    EXPECT_FALSE(panel->field("center")->isEnabled()) << "a wall has no centre";
    const int steps = undo()->count();
    type("radius_mm", "70");
    EXPECT_DOUBLE_EQ(scenery()[size_t(wall)].radius, 0.07);
    EXPECT_EQ(undo()->count(), steps + 1);
    type("radius_mm", "-5");
    EXPECT_THAT(panel->errorLabel()->text().toStdString(),
                HasSubstr(QString("scenery[%1].radius").arg(wall).toStdString()));
    EXPECT_DOUBLE_EQ(scenery()[size_t(wall)].radius, 0.07) << "refused: unchanged";
    EXPECT_EQ(panel->field("radius_mm")->text(), "70") << "the model's value again";
    type("end", "0.11, 0.01");
    EXPECT_THAT(panel->errorLabel()->text().toStdString(), HasSubstr("is not three numbers"));
    const sim::Vec3 start = scenery()[size_t(wall)].start;
    type("end", QString("%1, %2, %3").arg(start.x(), 0, 'g', 17).arg(start.y(), 0, 'g', 17).arg(start.z(), 0, 'g', 17));
    EXPECT_THAT(panel->errorLabel()->text().toStdString(), HasSubstr("end: must differ from start"));
    type("name", "fat");
    EXPECT_THAT(panel->errorLabel()->text().toStdString(),
                HasSubstr(QString("scenery[%1].name").arg(wall).toStdString()));
    EXPECT_EQ(scenery()[size_t(wall)].name, "wall");
    panel->facing()->setCurrentIndex(panel->facing()->currentIndex() == 0 ? 1 : 0);
    EXPECT_NE(scenery()[size_t(wall)].inward, inward0);
    EXPECT_EQ(undo()->count(), steps + 2);
    test::saveShot("surroundings_dock");
    undo()->undo();
    undo()->undo();
    EXPECT_EQ(scenery()[size_t(wall)].inward, inward0);
    EXPECT_DOUBLE_EQ(scenery()[size_t(wall)].radius, radius0);
}

TEST_F(SurroundingsFixture, AddAndRemoveAreOneStepEachAndTheTreeListsThem) {
    const size_t before = scenery().size();
    const int steps = undo()->count();
    QTest::mouseClick(panel->addFloorButton(), Qt::LeftButton);
    ASSERT_EQ(scenery().size(), before + 1) << panel->errorLabel()->text().toStdString();
    EXPECT_EQ(scenery().back().name, "floor");
    EXPECT_EQ(scenery().back().generator, studio::SceneryProject::Generator::Disc);
    EXPECT_EQ(w->document()->project().sceneryTextures.size(), before + 1) << "a texture slot each";
    EXPECT_EQ(undo()->count(), steps + 1);
    EXPECT_EQ(panel->selected(), static_cast<int>(before)) << "the new one is selected";
    auto* tree = w->findChild<QTreeWidget*>();
    ASSERT_NE(tree, nullptr);
    const auto found = tree->findItems("Surroundings", Qt::MatchExactly);
    ASSERT_EQ(found.size(), 1);
    EXPECT_EQ(found[0]->childCount(), static_cast<int>(before + 1));
    QTest::mouseClick(panel->addWallButton(), Qt::LeftButton);
    EXPECT_EQ(scenery().back().name, "wall");
    QTest::mouseClick(panel->removeButton(), Qt::LeftButton);
    EXPECT_EQ(scenery().size(), before + 1);
    EXPECT_EQ(undo()->count(), steps + 3);
    undo()->undo();
    EXPECT_EQ(scenery().back().name, "wall");
    undo()->undo();
    undo()->undo();
    EXPECT_EQ(scenery().size(), before);
}

} // namespace

TEST_F(SurroundingsFixture, ASurroundingsMaterialMapsAreEditedInTheMaterialMapsDockAsUndoSteps) {
    const int wall = row("pelvic_wall");
    ASSERT_GE(wall, 0);
    const std::vector<std::optional<studio::TextureProject>> before = w->document()->project().sceneryTextures;
    ASSERT_TRUE(before.at(static_cast<size_t>(wall)).has_value()) << "the sample's wall has a texture";
    // a click on the wall's row, then Material maps…: the dock in front, on the wall
    QListWidget* list = panel->list();
    QTest::mouseClick(list->viewport(), Qt::LeftButton, {}, list->visualItemRect(list->item(wall)).center());
    ASSERT_EQ(panel->selected(), wall);
    QTest::mouseClick(panel->mapsButton(), Qt::LeftButton);
    QCoreApplication::processEvents();
    studio::TexturePanel* maps = w->texturePanel();
    EXPECT_TRUE(maps->isVisible()) << "the Material maps dock came to the front";
    EXPECT_EQ(maps->targetKind(), studio::TexturePanel::Target::Scenery);
    EXPECT_EQ(maps->targetIndex(), wall);
    EXPECT_EQ(maps->tilesField()->text(), "20");
    // tiles per metre typed and applied: one undo step on the wall's block alone
    const int steps = undo()->index();
    maps->tilesField()->setFocus();
    QTest::keyClick(maps->tilesField(), Qt::Key_A, Qt::ControlModifier);
    QTest::keyClicks(maps->tilesField(), "32");
    QTest::mouseClick(maps->applyButton(), Qt::LeftButton);
    const auto& after = w->document()->project().sceneryTextures;
    ASSERT_TRUE(after.at(static_cast<size_t>(wall)).has_value());
    EXPECT_FLOAT_EQ(after[static_cast<size_t>(wall)]->tilesPerMetre, 32.0f)
        << maps->statusLabel()->text().toStdString();
    EXPECT_EQ(undo()->index(), steps + 1);
    for (size_t k = 0; k < after.size(); ++k)
        if (static_cast<int>(k) != wall) EXPECT_EQ(after[k], before[k]) << "scenery[" << k << "] untouched";
    // a refused value: the rule shown, the model as it was
    QTest::keyClick(maps->tilesField(), Qt::Key_A, Qt::ControlModifier);
    QTest::keyClicks(maps->tilesField(), "-4");
    QTest::mouseClick(maps->applyButton(), Qt::LeftButton);
    EXPECT_THAT(maps->statusLabel()->text().toStdString(), HasSubstr("tiles_per_metre"));
    EXPECT_FLOAT_EQ(w->document()->project().sceneryTextures[static_cast<size_t>(wall)]->tilesPerMetre, 32.0f);
    EXPECT_EQ(undo()->index(), steps + 1);
    // Remove, then undo twice: the sample's block again
    QTest::mouseClick(maps->removeButton(), Qt::LeftButton);
    EXPECT_FALSE(w->document()->project().sceneryTextures[static_cast<size_t>(wall)].has_value());
    undo()->undo();
    undo()->undo();
    EXPECT_EQ(w->document()->project().sceneryTextures, before);
    // a new floor has no maps; New generator gives it one as one step
    QTest::mouseClick(panel->addFloorButton(), Qt::LeftButton);
    const int floor = static_cast<int>(scenery().size()) - 1;
    EXPECT_EQ(maps->targetIndex(), floor) << "the new floor is the one shown";
    EXPECT_FALSE(maps->removeButton()->isEnabled()) << "no maps yet";
    const int beforeNew = undo()->index();
    QTest::mouseClick(maps->newButton(), Qt::LeftButton);
    ASSERT_TRUE(w->document()->project().sceneryTextures.at(static_cast<size_t>(floor)).has_value())
        << maps->statusLabel()->text().toStdString();
    EXPECT_FALSE(w->document()->project().sceneryTextures[static_cast<size_t>(floor)]->generator.empty());
    EXPECT_EQ(undo()->index(), beforeNew + 1);
    test::saveShot("surroundings_material_maps");
}

TEST_F(SurroundingsFixture, AnImportedMeshIsStaticAnatomyAddedAsOneStepWithItsUnitGuessed) {
    const std::filesystem::path source = scratch.dir / "bought";
    studio::writeHepatocysticAnatomy(source);
    const size_t before = scenery().size();
    const int steps = undo()->index();
    // Import mesh…: the dialog opens where the last anatomy came from; the liver's name typed, Open
    QSettings().setValue("studio/anatomyFolder", QString::fromStdString(source.string()));
    QTest::mouseClick(panel->importButton(), Qt::LeftButton);
    QFileDialog* dlg = nullptr;
    ASSERT_TRUE(
        test::waitFor([&] { return (dlg = w->findChild<QFileDialog*>("sceneryImportDialog")) != nullptr; }, 5000));
    ASSERT_TRUE(test::waitFor([&] { return dlg->isVisible(); }, 5000));
    auto* name = dlg->findChild<QLineEdit*>("fileNameEdit");
    ASSERT_NE(name, nullptr);
    auto* list = dlg->findChild<QListView*>("listView");
    ASSERT_NE(list, nullptr);
    ASSERT_TRUE(test::waitFor([&] { return list->model()->rowCount(list->rootIndex()) == 5; }, 5000))
        << "the five parts listed";
    name->setFocus();
    QTest::keyClicks(name, "liver.obj");
    auto* box = dlg->findChild<QDialogButtonBox*>("buttonBox");
    ASSERT_NE(box, nullptr);
    QTest::mouseClick(box->button(QDialogButtonBox::Open), Qt::LeftButton);
    ASSERT_TRUE(test::waitFor([&] { return scenery().size() == before + 1; }, 10000))
        << panel->errorLabel()->text().toStdString();
    const studio::SceneryProject& liver = scenery().back();
    EXPECT_EQ(liver.name, "liver");
    EXPECT_EQ(liver.generator, studio::SceneryProject::Generator::File);
    EXPECT_EQ(liver.file.parent_path().filename(), "anatomy") << "copied into the project";
    EXPECT_TRUE(std::filesystem::exists(liver.file));
    EXPECT_DOUBLE_EQ(liver.scale, 1.0) << "a liver 0.18 units long: metres";
    EXPECT_THAT(panel->unitGuess().toStdString(), HasSubstr("looks like metres"));
    EXPECT_EQ(undo()->index(), steps + 1);
    EXPECT_EQ(studio::Document::check(w->document()->project()), "") << "the model passes the rules of load";
    EXPECT_GT(studio::scenerySurface(liver).triangleCount(), 1000u);
    if (const char* shots = std::getenv("VISCERA_GUI_SHOTS"); shots && *shots) { // the liver in the viewport
        const int meshes = w->viewport()->meshCount();
        const bool shown = test::waitFor(
            [&] {
                for (const auto& m : w->viewport()->view().meshes())
                    if (m.name == "liver") return true;
                return false;
            },
            20000);
        EXPECT_TRUE(shown) << "the preview draws the imported liver; log:\n"
                           << w->log()->toPlainText().toStdString() << " meshes " << meshes;
        w->viewport()->frameAll();
        QTest::qWait(300);
        w->viewport()->grabFramebuffer().save(QString(shots) + "/surroundings_imported_liver_viewport.png");
    }
    // only its name and scale are fields; the primitives' geometry is not
    EXPECT_TRUE(panel->field("scale")->isEnabled());
    EXPECT_FALSE(panel->field("radius_mm")->isEnabled());
    EXPECT_FALSE(panel->field("start")->isEnabled());
    type("scale", "0.5");
    EXPECT_DOUBLE_EQ(scenery().back().scale, 0.5);
    EXPECT_EQ(undo()->index(), steps + 2);
    type("scale", "-1");
    EXPECT_THAT(panel->errorLabel()->text().toStdString(), HasSubstr("scale"));
    EXPECT_DOUBLE_EQ(scenery().back().scale, 0.5);
    EXPECT_EQ(undo()->index(), steps + 2);
    // the tree lists it; undo takes it out again
    undo()->undo();
    undo()->undo();
    EXPECT_EQ(scenery().size(), before);
    // a file that is no surface is refused naming the file, the model as it was
    std::ofstream(scratch.dir / "broken.obj") << "v 0 0 0\nv 1 0 0\nf 1 2 7\n";
    const QString why = panel->importFile(QString::fromStdString((scratch.dir / "broken.obj").string()));
    EXPECT_THAT(why.toStdString(), HasSubstr("broken"));
    EXPECT_EQ(scenery().size(), before);
    test::saveShot("surroundings_imported_liver");
}
