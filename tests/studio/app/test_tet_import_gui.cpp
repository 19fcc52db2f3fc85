// File → Import tet mesh… [issue 57 item 7]: a Gmsh .msh in centimetres, chosen in the dialog,
// its unit guessed and confirmed, becomes a tet body of the right size as one undo step (the file
// copied into the project, the mesh used as it is); a malformed file is refused naming the file,
// the line and the rule, the project and its folder unchanged; the body survives save and load.
#include "app/document.hpp"
#include "app/main_window.hpp"
#include "app/tet_import.hpp"
#include "gui_test_support.hpp"
#include "project/project.hpp"
#include "sim/mesh/generators.hpp"
#include "sim/mesh/gmsh_io.hpp"
#include "window_fixture.hpp"

#include <QAction>
#include <QComboBox>
#include <QDialogButtonBox>
#include <QFileDialog>
#include <QInputDialog>
#include <QLineEdit>
#include <QPlainTextEdit>
#include <QPushButton>
#include <QUndoStack>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>

namespace {

using namespace viscera;
namespace fs = std::filesystem;
using ::testing::HasSubstr;

/// A 4 × 3 × 2 cm block of tetrahedra written as Gmsh 2.2 ASCII in centimetres.
void writeBlockMsh(const fs::path& path) {
    sim::BoxSpec spec;
    spec.size = sim::Vec3(0.04, 0.03, 0.02);
    spec.cells = {4, 3, 2};
    const auto mesh = sim::makeBoxTetMesh(spec);
    std::ofstream out(path);
    out << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n" << mesh->vertexCount() << "\n";
    for (size_t i = 0; i < mesh->vertexCount(); ++i) {
        const sim::Vec3 p = mesh->positions()[i] * 100;
        out << i + 1 << " " << p.x() << " " << p.y() << " " << p.z() << "\n";
    }
    out << "$EndNodes\n$Elements\n" << mesh->tets().size() << "\n";
    for (size_t t = 0; t < mesh->tets().size(); ++t) {
        const sim::Tet& e = mesh->tets()[t];
        out << t + 1 << " 4 2 1 1 " << e[0] + 1 << " " << e[1] + 1 << " " << e[2] + 1 << " " << e[3] + 1 << "\n";
    }
    out << "$EndElements\n";
}

struct TetImportFixture : test::MainWindowFixture {
    fs::path project, source;
    TetImportFixture() : MainWindowFixture("viscera-gui-tetimport") {}
    void SetUp() override {
        MainWindowFixture::SetUp();
        project = open("tissue-slab");
        fs::create_directories(scratch.dir / "from-gmsh");
        source = scratch.dir / "from-gmsh" / "block.msh";
        writeBlockMsh(source);
    }
    const studio::Project& model() const { return w->document()->project(); }
};

TEST_F(TetImportFixture, AMshInCentimetresBecomesATetBodyOfTheRightSizeAsOneUndoStep) {
    const size_t bodies = model().bodies.size();
    const int steps = w->document()->undoStack()->count();
    w->tetImport()->action()->trigger();
    QFileDialog* files = nullptr;
    ASSERT_TRUE(
        test::waitFor([&] { return (files = w->findChild<QFileDialog*>("importTetMeshDialog")) != nullptr; }, 5000));
    // the file chosen in the dialog, then its Open button
    files->selectFile(QString::fromStdString(source.string()));
    auto* buttons = files->findChild<QDialogButtonBox*>("buttonBox");
    ASSERT_NE(buttons, nullptr);
    ASSERT_TRUE(test::waitFor([&] { return buttons->button(QDialogButtonBox::Open)->isEnabled(); }, 5000));
    QTest::mouseClick(buttons->button(QDialogButtonBox::Open), Qt::LeftButton);
    QInputDialog* unit = nullptr;
    ASSERT_TRUE(test::waitFor([&] { return (unit = w->findChild<QInputDialog*>("tetUnitDialog")) != nullptr; }, 5000));
    EXPECT_EQ(unit->textValue(), "centimetres") << "4 units long: guessed centimetres";
    EXPECT_THAT(unit->labelText().toStdString(), HasSubstr("'block.msh': 144 tetrahedra"));
    test::saveShot("tet_import_unit");
    auto* box = unit->findChild<QDialogButtonBox*>();
    ASSERT_NE(box, nullptr);
    QTest::mouseClick(box->button(QDialogButtonBox::Ok), Qt::LeftButton);
    ASSERT_EQ(model().bodies.size(), bodies + 1) << w->log()->toPlainText().toStdString();
    EXPECT_EQ(w->document()->undoStack()->count(), steps + 1);
    const studio::BodyProject& b = model().bodies.back();
    EXPECT_EQ(b.scene.name, "block");
    EXPECT_EQ(b.mesh.kind, studio::MeshSource::Kind::File);
    EXPECT_DOUBLE_EQ(b.mesh.scale, 0.01);
    EXPECT_EQ(b.mesh.file.parent_path(), project / "anatomy") << "copied into the project";
    const auto mesh = sim::readTetFile(b.mesh.file, b.mesh.scale);
    sim::Vec3 lo = mesh->positions()[0], hi = lo;
    for (const auto& p : mesh->positions())
        lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    EXPECT_NEAR((hi - lo).x(), 0.04, 1e-9) << "4 cm long";
    EXPECT_EQ(mesh->tets().size(), 144u) << "used as it is: no remeshing";
    test::saveShot("tet_import_done");
    // saved and read back: the same body, no meshing settings for a tet file
    ASSERT_TRUE(w->saveProject());
    const studio::Project again = studio::loadProject(project);
    EXPECT_EQ(again.bodies.back().mesh.file, b.mesh.file);
    EXPECT_DOUBLE_EQ(again.bodies.back().mesh.scale, 0.01);
    w->document()->undoStack()->undo();
    EXPECT_EQ(model().bodies.size(), bodies);
}

TEST_F(TetImportFixture, AMalformedFileIsRefusedAndTheProjectAndItsFolderAreUnchanged) {
    const fs::path bad = scratch.dir / "from-gmsh" / "binary.msh";
    std::ofstream(bad) << "$MeshFormat\n4.1 1 8\n$EndMeshFormat\n";
    const size_t bodies = model().bodies.size();
    const QString why = w->tetImport()->importFile(QString::fromStdString(bad.string()), bake::LengthUnit::Metre);
    EXPECT_THAT(why.toStdString(), HasSubstr("binary.msh: line 2: a binary .msh is not read"));
    EXPECT_EQ(model().bodies.size(), bodies);
    EXPECT_FALSE(fs::exists(project / "anatomy" / "binary.msh")) << "nothing copied";
    // a second import of the same good file gets a new name
    ASSERT_EQ(w->tetImport()->importFile(QString::fromStdString(source.string()), bake::LengthUnit::Centimetre), "");
    ASSERT_EQ(w->tetImport()->importFile(QString::fromStdString(source.string()), bake::LengthUnit::Centimetre), "");
    EXPECT_EQ(model().bodies.back().scene.name, "block_2");
    EXPECT_TRUE(fs::exists(project / "anatomy" / "block-2.msh"));
}

} // namespace
