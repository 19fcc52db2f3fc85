// The "Surroundings" dock [issue 57 item 1]: the static anatomy around the tissue (scenery walls
// and floors) listed, added, removed and edited by typed values, each one undo step through the
// Document checked by the project reader's rule for "scenery"; refusals name the field and rule
// and leave the model unchanged; undo restores; the project tree lists them.
#include "app/document.hpp"
#include "app/main_window.hpp"
#include "app/surroundings_panel.hpp"
#include "app/texture_panel.hpp"
#include "gui_test_support.hpp"
#include "window_fixture.hpp"

#include <QComboBox>
#include <QDockWidget>
#include <QLabel>
#include <QLineEdit>
#include <QListWidget>
#include <QPushButton>
#include <QTreeWidget>
#include <QUndoStack>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

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
    const int wall = row("pelvic_wall");
    ASSERT_GE(wall, 0);
    panel->list()->setCurrentRow(wall);
    EXPECT_EQ(panel->field("radius_mm")->text(), "75");
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
    type("end", "-0.1, 0.01, -0.025");
    EXPECT_THAT(panel->errorLabel()->text().toStdString(), HasSubstr("end: must differ from start"));
    type("name", "fat");
    EXPECT_THAT(panel->errorLabel()->text().toStdString(),
                HasSubstr(QString("scenery[%1].name").arg(wall).toStdString()));
    EXPECT_EQ(scenery()[size_t(wall)].name, "pelvic_wall");
    panel->facing()->setCurrentIndex(1);
    EXPECT_FALSE(scenery()[size_t(wall)].inward);
    EXPECT_EQ(undo()->count(), steps + 2);
    test::saveShot("surroundings_dock");
    undo()->undo();
    undo()->undo();
    EXPECT_TRUE(scenery()[size_t(wall)].inward);
    EXPECT_DOUBLE_EQ(scenery()[size_t(wall)].radius, 0.075);
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
