// Import anatomy's unit, scale and rotation [issue 57 item 7] driven as an artist would under
// Xvfb: a centimetre OBJ made here (a 12 × 8 × 6 cm box, the unit of SOFA's liver-smooth.obj)
// picked in the file dialog; the unit guessed and said with the size; the unit and the Y-up
// rotation chosen with synthetic clicks and keys; the body's parts then come in at the right size
// in metres; one undo step; the Properties fields edit the placement by the reader's rule.
#include "app/anatomy_steps.hpp"
#include "app/document.hpp"
#include "app/import_placement.hpp"
#include "app/properties_panel.hpp"
#include "bake/import.hpp"
#include "window_fixture.hpp"

#include <QAction>
#include <QApplication>
#include <QComboBox>
#include <QDialogButtonBox>
#include <QDoubleSpinBox>
#include <QFileDialog>
#include <QLabel>
#include <QListView>
#include <QPlainTextEdit>
#include <QPushButton>
#include <QSettings>
#include <QUndoStack>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

using namespace viscera;
namespace fs = std::filesystem;

namespace {

/// An axis-aligned box from `lo` to `hi` (file units) as an OBJ of 8 vertices and 12 triangles,
/// outward facing.
void writeBoxObj(const fs::path& file, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
    std::ofstream f(file);
    for (int c = 0; c < 8; ++c)
        f << "v " << (c & 1 ? hi : lo).x() << ' ' << (c & 2 ? hi : lo).y() << ' ' << (c & 4 ? hi : lo).z() << '\n';
    const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (const auto& q : quads)
        f << "f " << q[0] + 1 << ' ' << q[1] + 1 << ' ' << q[2] + 1 << "\nf " << q[0] + 1 << ' ' << q[2] + 1 << ' '
          << q[3] + 1 << '\n';
}

struct PlacementFixture : test::MainWindowFixture {
    PlacementFixture() : MainWindowFixture("viscera-import-placement-gui") {}

    studio::AnatomySteps* steps() { return w->anatomySteps(); }

    /// File → Import anatomy…, in the dialog (opened in `file`'s folder, where the last anatomy
    /// came from) `file` selected by Ctrl+A in the list and Open clicked; returns the unit question
    /// once the import check has passed.
    studio::ImportPlacementDialog* pickByDialog(const fs::path& file) {
        QSettings().setValue("studio/anatomyFolder", QString::fromStdString(file.parent_path().string()));
        steps()->importAction()->trigger();
        QFileDialog* dlg = nullptr;
        EXPECT_TRUE(
            test::waitFor([&] { return (dlg = w->findChild<QFileDialog*>("importAnatomyDialog")) != nullptr; }, 5000));
        if (!dlg) return nullptr;
        auto* list = dlg->findChild<QListView*>("listView");
        EXPECT_NE(list, nullptr);
        if (!list) return nullptr;
        EXPECT_TRUE(test::waitFor([&] { return list->model()->rowCount(list->rootIndex()) == 1; }, 5000))
            << "the folder holds the one OBJ";
        list->setFocus();
        QTest::keyClick(list, Qt::Key_A, Qt::ControlModifier);
        auto* box = dlg->findChild<QDialogButtonBox*>("buttonBox");
        EXPECT_NE(box, nullptr);
        if (!box) return nullptr;
        QTest::mouseClick(box->button(QDialogButtonBox::Open), Qt::LeftButton);
        EXPECT_TRUE(
            test::waitFor([&] { return steps()->placementDialog() && steps()->placementDialog()->isVisible(); }, 60000))
            << "no unit question; log: " << w->log()->toPlainText().toStdString()
            << "; task output: " << steps()->task().output().toStdString();
        return steps()->placementDialog();
    }
};

QString labelText(QWidget* dlg, const char* name) {
    auto* l = dlg->findChild<QLabel*>(name);
    return l ? l->text() : QString("<no label %1>").arg(name);
}

/// The parts of body `b` as the export imports them (project.cpp: placedOptions), their box.
std::array<sim::Vec3, 2> placedBounds(const studio::Project& p, size_t b) {
    const studio::RemeshSource& r = p.bodies.at(b).mesh.remesh;
    return bake::importSurface(r.parts.at(0).file, bake::placedOptions(r.placement)).bounds();
}

} // namespace

TEST_F(PlacementFixture, ACentimetreObjComesInAtItsSizeInMetresByGuiEvents) {
    const fs::path dir = open("tissue-slab");
    w->preview()->stop();
    steps()->task().setProgram(VISCERA_STUDIO_EXE);
    fs::create_directories(scratch.dir / "from");
    const fs::path obj = scratch.dir / "from" / "box-cm.obj"; // outside the project: copied in on import
    writeBoxObj(obj, Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(13, 10, 9));
    QUndoStack* undo = w->document()->undoStack();
    const int before = undo->count();

    studio::ImportPlacementDialog* dlg = pickByDialog(obj);
    ASSERT_NE(dlg, nullptr);
    EXPECT_EQ(dlg->guessedUnit(), bake::LengthUnit::Centimetre);
    EXPECT_TRUE(labelText(dlg, "unitGuess").contains("Looks like centimetres: 0.12 m long"))
        << labelText(dlg, "unitGuess").toStdString();
    EXPECT_EQ(labelText(dlg, "importSize"), "0.12 × 0.08 × 0.06 m");
    EXPECT_EQ(undo->count(), before) << "nothing enters the model before the question is answered";

    // the unit combo by keys: one down is millimetres (the size follows), one up centimetres again
    auto* unit = dlg->findChild<QComboBox*>("importUnit");
    ASSERT_NE(unit, nullptr);
    unit->setFocus();
    QTest::keyClick(unit, Qt::Key_Down);
    EXPECT_EQ(dlg->placement().unit, bake::LengthUnit::Millimetre);
    EXPECT_TRUE(labelText(dlg, "importSize").startsWith("0.012 × 0.008 × 0.006 m"))
        << labelText(dlg, "importSize").toStdString();
    QTest::keyClick(unit, Qt::Key_Up);
    EXPECT_EQ(dlg->placement().unit, bake::LengthUnit::Centimetre);
    // Y-up → Z-up: 90° about x, the depth and the height swap
    QTest::mouseClick(dlg->findChild<QPushButton*>("yUpToZUp"), Qt::LeftButton);
    EXPECT_EQ(labelText(dlg, "importSize"), "0.12 × 0.06 × 0.08 m");
    test::saveShot("import_placement");
    QTest::mouseClick(dlg->findChild<QPushButton*>("importButton"), Qt::LeftButton);

    ASSERT_TRUE(test::waitFor([&] { return w->document()->project().bodies.size() == 2; }, 5000))
        << w->log()->toPlainText().toStdString();
    EXPECT_EQ(undo->count(), before + 1) << "the import is one undo step";
    const studio::Project& p = w->document()->project();
    const bake::ImportPlacement& q = p.bodies[1].mesh.remesh.placement;
    EXPECT_EQ(q.unit, bake::LengthUnit::Centimetre);
    EXPECT_EQ(q.scale, 1.0);
    EXPECT_EQ(q.rotationDeg, Eigen::Vector3d(90, 0, 0));
    EXPECT_EQ(p.bodies[1].mesh.remesh.parts.at(0).file, dir / "anatomy" / "box-cm.obj");
    // (x, y, z) cm → (x, −z, y) m
    const auto [lo, hi] = placedBounds(p, 1);
    EXPECT_NEAR((lo - sim::Vec3(0.01, -0.09, 0.02)).cwiseAbs().maxCoeff(), 0.0, 1e-6) << lo.transpose();
    EXPECT_NEAR((hi - sim::Vec3(0.13, -0.03, 0.10)).cwiseAbs().maxCoeff(), 0.0, 1e-6) << hi.transpose();
    EXPECT_TRUE(w->log()->toPlainText().contains("in centimetres: 0.12 × 0.06 × 0.08 m"))
        << w->log()->toPlainText().toStdString();
    // saved and read back by the one reader: the same placement
    ASSERT_TRUE(w->saveProject());
    EXPECT_EQ(studio::loadProject(dir).bodies[1].mesh.remesh.placement, q);
    undo->undo();
    EXPECT_EQ(w->document()->project().bodies.size(), 1u);
}

TEST_F(PlacementFixture, TheUnitAloneGivesTheBoxInMetresAndThePropertiesEditItByTheReadersRule) {
    open("tissue-slab");
    w->preview()->stop();
    steps()->task().setProgram(VISCERA_STUDIO_EXE);
    fs::create_directories(scratch.dir / "from");
    const fs::path obj = scratch.dir / "from" / "cube-cm.obj";
    writeBoxObj(obj, Eigen::Vector3d(-6, -4, -3), Eigen::Vector3d(6, 4, 3));
    studio::ImportPlacementDialog* dlg = pickByDialog(obj);
    ASSERT_NE(dlg, nullptr);
    // the unit set to cm by the mouse: the combo's popup, the row clicked
    auto* unit = dlg->findChild<QComboBox*>("importUnit");
    unit->setCurrentIndex(0); // metres first, so the click changes it
    EXPECT_TRUE(labelText(dlg, "importSize").contains("longer than any organ")) << "12 m long in metres";
    QTest::mouseClick(unit, Qt::LeftButton);
    QAbstractItemView* popup = unit->view();
    ASSERT_TRUE(test::waitFor([&] { return popup->isVisible(); }, 3000));
    QTest::qWait(QApplication::doubleClickInterval() + 100); // the popup ignores a release that quick
    const QRect row = popup->visualRect(popup->model()->index(1, 0));
    QTest::mouseClick(popup->viewport(), Qt::LeftButton, Qt::NoModifier, row.center());
    ASSERT_EQ(dlg->placement().unit, bake::LengthUnit::Centimetre);
    QTest::mouseClick(dlg->findChild<QPushButton*>("importButton"), Qt::LeftButton);
    ASSERT_TRUE(test::waitFor([&] { return w->document()->project().bodies.size() == 2; }, 5000));
    const auto [lo, hi] = placedBounds(w->document()->project(), 1);
    EXPECT_NEAR((lo - sim::Vec3(-0.06, -0.04, -0.03)).cwiseAbs().maxCoeff(), 0.0, 1e-6) << lo.transpose();
    EXPECT_NEAR((hi - sim::Vec3(0.06, 0.04, 0.03)).cwiseAbs().maxCoeff(), 0.0, 1e-6) << hi.transpose();

    // the selected body's Properties: scale and rotation typed, each one undo step; a bad value
    // refused naming the field and the rule, the model unchanged
    ASSERT_EQ(w->selectedBody(), 1);
    QUndoStack* undo = w->document()->undoStack();
    const int steps0 = undo->count();
    EXPECT_EQ(w->setProperty("scale", "2"), "");
    EXPECT_EQ(w->document()->project().bodies[1].mesh.remesh.placement.scale, 2.0);
    EXPECT_EQ(undo->count(), steps0 + 1);
    const QString refused = w->setProperty("rotation_deg", "400 0 0");
    EXPECT_TRUE(refused.contains("bodies[1].mesh.remesh.rotation_deg")) << refused.toStdString();
    EXPECT_TRUE(refused.contains("must be in [-360, 360]")) << refused.toStdString();
    EXPECT_TRUE(w->setProperty("scale", "0").contains("bodies[1].mesh.remesh.scale: must be positive"));
    EXPECT_EQ(w->setProperty("unit", "ft"), "unit: 'ft' is not a length unit (m, cm, mm, inch)");
    EXPECT_EQ(w->document()->project().bodies[1].mesh.remesh.placement.rotationDeg, Eigen::Vector3d::Zero());
    EXPECT_EQ(undo->count(), steps0 + 1);
    EXPECT_EQ(w->setProperty("unit", "mm"), "");
    EXPECT_EQ(w->document()->project().bodies[1].mesh.remesh.placement.unit, bake::LengthUnit::Millimetre);
    undo->undo();
    undo->undo();
    EXPECT_EQ(w->document()->project().bodies[1].mesh.remesh.placement,
              (bake::ImportPlacement{bake::LengthUnit::Centimetre}));
}

TEST(ImportPlacement, TheGuessAndThePlacedSize) {
    EXPECT_EQ(bake::guessLengthUnit(6.4), bake::LengthUnit::Centimetre) << "SOFA's liver-smooth.obj";
    EXPECT_EQ(bake::guessLengthUnit(12), bake::LengthUnit::Centimetre);
    EXPECT_EQ(bake::guessLengthUnit(250), bake::LengthUnit::Millimetre);
    EXPECT_EQ(bake::guessLengthUnit(0.25), bake::LengthUnit::Metre);
    EXPECT_EQ(bake::guessLengthUnit(0), bake::LengthUnit::Metre);
    const std::array<Eigen::Vector3d, 2> b{Eigen::Vector3d(-1, 0, 0), Eigen::Vector3d(13, 10, 9)};
    bake::ImportPlacement inch{bake::LengthUnit::Inch};
    EXPECT_NEAR(studio::placedSize(b, inch).x(), 14 * 0.0254, 1e-12);
}
