// Renaming and deleting a body in the project tree [issue 57 item 7]: F2, Delete and the body's
// context menu, driven with synthetic keys; each edit one undo step through the Document, checked
// by the project reader's rules; a refused name or a referenced body names the field and the rule
// and leaves the model unchanged; the references follow a rename; undo restores the model exactly.
#include "app/document.hpp"
#include "app/error_banner.hpp"
#include "app/main_window.hpp"
#include "app/project_tree_panel.hpp"
#include "app/properties_panel.hpp"
#include "gui_test_support.hpp"
#include "project/project.hpp"
#include "window_fixture.hpp"

#include <QAction>
#include <QInputDialog>
#include <QLabel>
#include <QLineEdit>
#include <QMenu>
#include <QMessageBox>
#include <QSignalSpy>
#include <QTimer>
#include <QUndoStack>

#include <gtest/gtest.h>

namespace {

using namespace viscera;
namespace fs = std::filesystem;

struct BodyEditFixture : test::MainWindowFixture {
    studio::ProjectTreePanel* tree = nullptr;
    BodyEditFixture() : MainWindowFixture("viscera-gui-bodies") {}
    void SetUp() override {
        MainWindowFixture::SetUp();
        tree = w->projectTree();
        ASSERT_NE(tree, nullptr);
    }
    const studio::Project& project() { return w->document()->project(); }
    std::string text() { return studio::projectJsonText(project()); }
    QUndoStack* undo() { return w->document()->undoStack(); }
    /// The body item named `name` (under "Bodies"), or null.
    QTreeWidgetItem* bodyItem(const std::string& name) {
        QTreeWidgetItem* bodies = tree->topLevelItem(0);
        for (int i = 0; bodies && i < bodies->childCount(); ++i)
            if (bodies->child(i)->text(0).toStdString() == name) return bodies->child(i);
        return nullptr;
    }
    /// Opens `item`'s context menu with a synthetic right-click event; returns the texts of its
    /// actions and triggers the one named `trigger` (none when null) before the menu closes.
    QStringList contextMenu(QTreeWidgetItem* item, const char* trigger = nullptr) {
        return MainWindowFixture::contextMenu(tree, item, trigger);
    }
    /// Types `value` into the Properties field `name` as a user does: select all, type, Return.
    void typeProperty(const char* name, const QString& value) {
        QLineEdit* e = nullptr;
        ASSERT_TRUE(
            test::waitFor([&] { return (e = w->propertiesPanel()->findChild<QLineEdit*>(name)) != nullptr; }, 2000))
            << name;
        e->setFocus();
        QTest::keyClick(e, Qt::Key_A, Qt::ControlModifier);
        QTest::keyClicks(e, value);
        QTest::keyClick(e, Qt::Key_Return);
        QCoreApplication::processEvents();
    }
    /// Clicks the body's item and gives the tree the focus.
    void pick(const std::string& name) {
        QTreeWidgetItem* item = bodyItem(name);
        ASSERT_NE(item, nullptr) << name;
        tree->scrollToItem(item);
        test::click(tree->viewport(), tree->visualItemRect(item).center());
        tree->setFocus();
        ASSERT_EQ(tree->currentItem(), item);
    }
    /// F2 on the tree, `name` typed into the dialog over the old name, Return.
    void renameWithKeys(const std::string& body, const QString& name) {
        pick(body);
        QTest::keyClick(tree, Qt::Key_F2);
        ASSERT_TRUE(test::waitFor([&] { return tree->renameDialog() && tree->renameDialog()->isVisible(); }, 2000));
        QInputDialog* dialog = tree->renameDialog();
        EXPECT_EQ(dialog->objectName(), "renameBodyDialog");
        auto* field = dialog->findChild<QLineEdit*>();
        ASSERT_NE(field, nullptr);
        EXPECT_EQ(field->text().toStdString(), body) << "the dialog starts from the old name";
        field->setFocus();
        field->selectAll();
        if (name.isEmpty())
            QTest::keyClick(field, Qt::Key_Delete);
        else
            QTest::keyClicks(field, name);
        QTest::keyClick(field, Qt::Key_Return);
        ASSERT_TRUE(test::waitFor([&] { return !tree->renameDialog(); }, 2000)) << "OK closes the dialog";
        QCoreApplication::processEvents();
    }
};

TEST_F(BodyEditFixture, RenameIsOneUndoStepAndEveryReferenceFollows) {
    open("rectum");
    QSignalSpy refused(tree, &studio::ProjectTreePanel::refused);
    const std::string before = text();
    const int steps = undo()->count();

    renameWithKeys("vessel", "artery");
    EXPECT_EQ(tree->lastRefusal().toStdString(), "");
    EXPECT_EQ(refused.count(), 0);
    EXPECT_EQ(undo()->count(), steps + 1) << "one rename, one undo step";
    ASSERT_EQ(project().bodies.size(), 2u);
    EXPECT_EQ(project().bodies[1].scene.name, "artery");
    const auto& instruments = project().scene.interaction->instruments;
    EXPECT_EQ(instruments[2].target, "artery") << "the clip applier's target follows";
    ASSERT_TRUE(project().scene.assessment && project().scene.assessment->vessel);
    EXPECT_EQ(project().scene.assessment->vessel->body, "artery") << "the vessel to protect follows";
    EXPECT_NE(bodyItem("artery"), nullptr) << "the tree shows the new name";
    EXPECT_EQ(bodyItem("vessel"), nullptr);

    renameWithKeys("fat", "mesorectum");
    EXPECT_EQ(tree->lastRefusal().toStdString(), "");
    EXPECT_EQ(undo()->count(), steps + 2);
    EXPECT_EQ(project().bodies[0].scene.name, "mesorectum");
    EXPECT_EQ(project().bodies[1].scene.embeddedIn, "mesorectum") << "embedded_in follows";
    EXPECT_EQ(project().surfaces[0].scene.attachTo, "mesorectum") << "from_boundary_of follows";
    EXPECT_EQ(project().scene.interaction->tissues[1].layer, "mesorectum") << "the tissue layer follows";
    // The renamed project passes the reader's rules (loads back from its own text).
    EXPECT_EQ(studio::Document::check(project()).toStdString(), "");
    const std::string renamed = text();

    undo()->undo();
    undo()->undo();
    EXPECT_EQ(text(), before) << "undo restores the model exactly";
    EXPECT_NE(bodyItem("vessel"), nullptr);
    undo()->redo();
    undo()->redo();
    EXPECT_EQ(text(), renamed);
}

TEST_F(BodyEditFixture, RefusedNamesNameTheFieldAndRuleAndChangeNothing) {
    const fs::path dir = open("rectum");
    QSignalSpy refused(tree, &studio::ProjectTreePanel::refused);
    const std::string before = text(), origin = (dir / "project.json").string();
    const int steps = undo()->count();

    struct Case {
        QString name;
        std::string rule;
    };
    const Case cases[] = {
        {"fat", "'fat' is used twice"},       // another body
        {"fascia", "'fascia' is used twice"}, // a surface: the reader's one set of names
        {"", "must be 1-64 characters of [A-Za-z0-9_-]"},
        {"blood vessel", "must be 1-64 characters of [A-Za-z0-9_-]"},
        {"vessel/2", "must be 1-64 characters of [A-Za-z0-9_-]"},
    };
    for (const Case& c : cases) {
        renameWithKeys("vessel", c.name);
        EXPECT_EQ(tree->lastRefusal().toStdString(), origin + ": bodies[1].name: " + c.rule) << c.name.toStdString();
        ASSERT_FALSE(refused.isEmpty());
        EXPECT_EQ(refused.takeLast().at(0).toString(), tree->lastRefusal()) << "sent to whoever shows it";
        EXPECT_EQ(undo()->count(), steps) << "no undo step";
        EXPECT_EQ(text(), before) << "the model is unchanged";
        EXPECT_NE(bodyItem("vessel"), nullptr);
    }
    // The same name: nothing to do, no undo step and no refusal.
    renameWithKeys("vessel", "vessel");
    EXPECT_EQ(tree->lastRefusal().toStdString(), "");
    EXPECT_EQ(undo()->count(), steps);
}

TEST_F(BodyEditFixture, DeleteIsOneUndoStepAndUndoRestoresTheBodyExactly) {
    open("liver");
    QSignalSpy refused(tree, &studio::ProjectTreePanel::refused);
    const std::string before = text();
    const int steps = undo()->count();
    ASSERT_EQ(project().bodies.size(), 2u);

    pick("vessel"); // embedded in the organ; nothing names it
    QTest::keyClick(tree, Qt::Key_Delete);
    QCoreApplication::processEvents();
    EXPECT_EQ(tree->lastRefusal().toStdString(), "");
    EXPECT_EQ(refused.count(), 0);
    EXPECT_EQ(undo()->count(), steps + 1) << "one delete, one undo step";
    ASSERT_EQ(project().bodies.size(), 1u);
    EXPECT_EQ(project().bodies[0].scene.name, "organ");
    EXPECT_EQ(bodyItem("vessel"), nullptr) << "the tree lost the body";
    EXPECT_EQ(studio::Document::check(project()).toStdString(), "");
    const std::string deleted = text();

    undo()->undo();
    EXPECT_EQ(text(), before) << "undo brings the body back exactly (material, mesh, embedding)";
    EXPECT_NE(bodyItem("vessel"), nullptr);
    undo()->redo();
    EXPECT_EQ(text(), deleted);
}

TEST_F(BodyEditFixture, DeletingAReferencedBodyIsRefusedNamingTheReferences) {
    const fs::path dir = open("rectum");
    QSignalSpy refused(tree, &studio::ProjectTreePanel::refused);
    const std::string before = text(), origin = (dir / "project.json").string();
    const int steps = undo()->count();

    pick("fat");
    QTest::keyClick(tree, Qt::Key_Delete);
    QCoreApplication::processEvents();
    EXPECT_EQ(tree->lastRefusal().toStdString(),
              origin + ": bodies[0].name: 'fat' is named by bodies[1].embedded_in, surfaces[0].from_boundary_of, "
                       "interaction.tissues[1].layer (change or delete that first)");
    pick("vessel");
    tree->deleteBodyAction()->trigger(); // the context menu's action
    EXPECT_EQ(tree->lastRefusal().toStdString(),
              origin + ": bodies[1].name: 'vessel' is named by interaction.instruments[2].target, "
                       "assessment.targets.vessel.body (change or delete that first)");
    EXPECT_EQ(refused.count(), 2);
    EXPECT_EQ(undo()->count(), steps) << "no undo step";
    EXPECT_EQ(text(), before) << "the model is unchanged";
    EXPECT_EQ(project().bodies.size(), 2u);
}

TEST_F(BodyEditFixture, TheBodyItemsContextMenuRenamesAndDeletes) {
    open("liver");
    // The menu opens on a body item only, with the two actions.
    QTreeWidgetItem* item = bodyItem("vessel");
    ASSERT_NE(item, nullptr);
    const QStringList shown = contextMenu(item);
    EXPECT_EQ(shown, (QStringList{"Rename body…", "Delete body", "Add tissue layer"}));
    EXPECT_EQ(tree->currentItem(), item) << "the menu acts on the item it opened on";
    EXPECT_TRUE(tree->renameBodyAction()->isEnabled());

    // Not a body: the actions are off.
    tree->setCurrentItem(tree->topLevelItem(0)); // the "Bodies" group
    EXPECT_FALSE(tree->renameBodyAction()->isEnabled());
    EXPECT_FALSE(tree->deleteBodyAction()->isEnabled());

    // Rename through the action; the main window shows a refusal in its banner.
    pick("vessel");
    tree->renameBodyAction()->trigger();
    ASSERT_TRUE(test::waitFor([&] { return tree->renameDialog() && tree->renameDialog()->isVisible(); }, 2000));
    tree->renameDialog()->setTextValue("organ");
    tree->renameDialog()->accept();
    ASSERT_TRUE(test::waitFor([&] { return !tree->lastRefusal().isEmpty(); }, 2000));
    EXPECT_NE(tree->lastRefusal().toStdString().find("bodies[1].name: 'organ' is used twice"), std::string::npos);
    EXPECT_EQ(w->errorBanner()->text(), tree->lastRefusal());
    EXPECT_EQ(project().bodies[1].scene.name, "vessel");
}

// A tissue layer added over a body from its context menu [issue 57 item 4: the peritoneum over
// Calot's triangle is such a layer]: one undo step, listed under Surfaces and selected; its region
// typed in Properties (a bad corner refused with the reader's rule, the model unchanged); Delete on
// the layer's item removes it in one step; undo restores the model exactly.
TEST_F(BodyEditFixture, ATissueLayerIsAddedOverABodyRegionedAndDeletedAsUndoSteps) {
    open("organ-blob");
    const std::string before = text();
    const int steps = undo()->count();
    QTreeWidgetItem* item = bodyItem("organ");
    ASSERT_NE(item, nullptr);
    const QStringList shown = contextMenu(item, "addLayerAction");
    EXPECT_TRUE(shown.contains("Add tissue layer"));
    ASSERT_EQ(project().surfaces.size(), 1u) << tree->lastRefusal().toStdString();
    EXPECT_EQ(project().surfaces[0].scene.name, "fascia");
    EXPECT_EQ(project().surfaces[0].scene.attachTo, "organ");
    EXPECT_FALSE(project().surfaces[0].region.has_value()) << "the whole boundary";
    EXPECT_EQ(undo()->count(), steps + 1);
    ASSERT_TRUE(test::waitFor([&] { return tree->currentLayer() == 0; }, 2000)) << "the new layer is selected";
    // its region typed: the top of the organ
    auto type = [&](const char* name, const QString& value) { typeProperty(name, value); };
    type("region_min", "-1 -1 0");
    ASSERT_TRUE(project().surfaces[0].region.has_value());
    EXPECT_DOUBLE_EQ((*project().surfaces[0].region)[0].z(), 0.0);
    EXPECT_DOUBLE_EQ((*project().surfaces[0].region)[1].z(), 1.0);
    EXPECT_EQ(undo()->count(), steps + 2);
    type("region_max", "1 1 -2");
    auto* error = w->propertiesPanel()->findChild<QLabel*>("propertyError");
    ASSERT_NE(error, nullptr);
    EXPECT_NE(error->text().toStdString().find("surfaces[0].region: min must not exceed max"), std::string::npos)
        << error->text().toStdString();
    type("region_max", "1 1");
    EXPECT_NE(error->text().toStdString().find("must be three numbers"), std::string::npos);
    EXPECT_DOUBLE_EQ((*project().surfaces[0].region)[1].z(), 1.0) << "refused: unchanged";
    EXPECT_EQ(undo()->count(), steps + 2);
    test::saveShot("layer_added");
    // Delete on the layer's item
    QTreeWidgetItem* layer = nullptr;
    for (int g = 0; g < tree->topLevelItemCount() && !layer; ++g)
        if (tree->topLevelItem(g)->text(0) == "Surfaces" && tree->topLevelItem(g)->childCount() > 0)
            layer = tree->topLevelItem(g)->child(0);
    ASSERT_NE(layer, nullptr) << "listed under Surfaces";
    EXPECT_EQ(layer->text(0), "fascia");
    tree->scrollToItem(layer);
    test::click(tree->viewport(), tree->visualItemRect(layer).center());
    tree->setFocus();
    ASSERT_EQ(tree->currentLayer(), 0);
    EXPECT_TRUE(tree->deleteLayerAction()->isEnabled());
    EXPECT_FALSE(tree->deleteBodyAction()->isEnabled());
    QTest::keyClick(tree, Qt::Key_Delete);
    EXPECT_TRUE(project().surfaces.empty());
    EXPECT_EQ(undo()->count(), steps + 3);
    undo()->undo();
    undo()->undo();
    undo()->undo();
    EXPECT_EQ(text(), before) << "undo restores the model exactly";
}

// The rectum's fascia is a tissue layer its hook cuts: deleting it takes it out of the
// interaction's tissues in the same undo step (the fat stays cut); undo restores both.
TEST_F(BodyEditFixture, DeletingALayerTheHookCutsTakesItOutOfTheTissues) {
    open("rectum");
    ASSERT_FALSE(project().surfaces.empty());
    const std::string before = text();
    const int steps = undo()->count();
    EXPECT_EQ(w->document()->removeLayer(0).toStdString(), "");
    EXPECT_TRUE(project().surfaces.empty());
    ASSERT_EQ(project().scene.interaction->tissues.size(), 1u);
    EXPECT_EQ(project().scene.interaction->tissues[0].layer, "fat");
    EXPECT_EQ(undo()->count(), steps + 1) << "one undo step";
    undo()->undo();
    EXPECT_EQ(text(), before) << "undo restores the layer and its tissue";
}

// A layer added under a hook that cuts the body alone [issue 57 item 4: the peritoneum over the
// cystic duct]: the layer enters the tissues the hook and the scissors cut, first, and the body
// under it takes the covered body's ignition and conductivity (a burn dose the hook's pass does
// not reach: it opens the layer, not the organ), in the same undo step; undo restores them.
TEST_F(BodyEditFixture, ALayerAddedUnderAHookIsWhatTheHookOpens) {
    open("organ-blob");
    ASSERT_TRUE(w->document()->project().surfaces.empty());
    const int body = 0;
    ASSERT_EQ(w->document()->addInstrument("Add a hook", sim::InstrumentDesc::Kind::EnergyHook, "right").toStdString(),
              "");
    ASSERT_EQ(project().scene.interaction->tissues.size(), 1u);
    EXPECT_TRUE(project().scene.interaction->bareBody) << "a studio interaction meets bare bodies too";
    const std::string organ = project().scene.interaction->tissues[0].layer;
    const std::string before = text();
    const int steps = undo()->count();
    ASSERT_EQ(w->document()->addLayer(body).toStdString(), "");
    const auto& tissues = project().scene.interaction->tissues;
    ASSERT_EQ(tissues.size(), 2u);
    EXPECT_EQ(tissues[0].layer, project().surfaces[0].scene.name);
    EXPECT_EQ(tissues[1].layer, organ);
    EXPECT_DOUBLE_EQ(tissues[1].ignitionC, studio::kCoveredBodyIgnitionC);
    EXPECT_DOUBLE_EQ(tissues[1].conductivity, studio::kCoveredBodyConductivity);
    EXPECT_EQ(undo()->count(), steps + 1);
    undo()->undo();
    EXPECT_EQ(text(), before) << "undo restores the tissues";
}

// A tissue layer picked in the tree: its stretch stiffness, areal density and subdivision rounds are
// typed in Properties, each one undo step checked by the project reader's rule for surfaces[i]; a
// refused value names the field and the rule and leaves the model unchanged; undo restores it.
TEST_F(BodyEditFixture, ALayersFieldsAreTypedUndoableEditsOfTheModel) {
    open("liver");
    QTreeWidgetItem* surface = nullptr;
    for (int g = 0; g < tree->topLevelItemCount() && !surface; ++g)
        if (tree->topLevelItem(g)->text(0) == "Surfaces" && tree->topLevelItem(g)->childCount() > 0)
            surface = tree->topLevelItem(g)->child(0);
    ASSERT_NE(surface, nullptr);
    tree->scrollToItem(surface);
    test::click(tree->viewport(), tree->visualItemRect(surface).center());
    ASSERT_EQ(tree->currentItem(), surface);
    QLineEdit* field = nullptr;
    ASSERT_TRUE(test::waitFor(
        [&] { return (field = w->propertiesPanel()->findChild<QLineEdit*>("subdivide")) != nullptr; }, 2000));
    EXPECT_EQ(field->text(), "0");
    auto* error = w->propertiesPanel()->findChild<QLabel*>("propertyError");
    ASSERT_NE(error, nullptr);
    auto type = [&](const char* name, const QString& value) { typeProperty(name, value); };
    const std::string before = text();
    const int steps = undo()->count();
    type("subdivide", "2");
    EXPECT_EQ(project().surfaces[0].subdivide, 2);
    EXPECT_EQ(undo()->count(), steps + 1);
    type("subdivide", "4");
    EXPECT_NE(error->text().toStdString().find("surfaces[0].subdivide: must be an integer in [0, 3]"),
              std::string::npos)
        << error->text().toStdString();
    type("subdivide", "1.5");
    EXPECT_NE(error->text().toStdString().find("must be a whole number"), std::string::npos);
    EXPECT_EQ(project().surfaces[0].subdivide, 2) << "refused: unchanged";
    type("stretch_stiffness", "-3");
    EXPECT_NE(error->text().toStdString().find("surfaces[0].stretch_stiffness"), std::string::npos)
        << error->text().toStdString();
    type("stretch_stiffness", "80");
    EXPECT_DOUBLE_EQ(project().surfaces[0].scene.stretchStiffness, 80);
    EXPECT_EQ(undo()->count(), steps + 2);
    test::saveShot("layer_properties");
    undo()->undo();
    undo()->undo();
    EXPECT_EQ(text(), before) << "undo restores the model exactly";
    EXPECT_TRUE(test::waitFor(
        [&] {
            auto* e = w->propertiesPanel()->findChild<QLineEdit*>("subdivide");
            return e && e->text() == "0";
        },
        2000))
        << "the field shows the model's value again";
}

} // namespace
