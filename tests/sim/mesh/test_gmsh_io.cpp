// Tetrahedral meshes from Gmsh (.msh 2.2 and 4.1 ASCII) and VTK (.vtu ASCII) [issue 57 item 7]:
// the same two-tetrahedron mesh read from each format gives the same mesh; surfaces are skipped,
// unused nodes dropped, negative tetrahedra turned positive, units scaled; every malformed file
// is refused with one line naming the file, the line or array, and the rule.
#include "sim/mesh/gmsh_io.hpp"
#include "sim/util/error.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>

namespace {

using namespace viscera;
using ::testing::HasSubstr;

// two tetrahedra sharing the face (2, 3, 4) of a unit-ish bipyramid, in centimetres; node 9 is
// a geometry point no tetrahedron uses; the second tetrahedron is listed with negative volume
const char* kMsh22 = R"($MeshFormat
2.2 0 8
$EndMeshFormat
$PhysicalNames
1
3 1 "organ"
$EndPhysicalNames
$Nodes
6
1 0 0 -1
2 1 0 0
3 0 1 0
4 0 0 0
5 0 0 1
9 5 5 5
$EndNodes
$Elements
4
1 15 2 0 1 9
2 2 2 0 1 2 3 4
3 4 2 1 1 1 2 3 4
4 4 2 1 1 5 2 3 4
$EndElements
)";

const char* kMsh41 = R"($MeshFormat
4.1 0 8
$EndMeshFormat
$Entities
0 0 0 1
1 0 0 -1 1 1 1 0 0
$EndEntities
$Nodes
2 6 1 9
0 1 0 1
9
5 5 5
3 1 0 5
1
2
3
4
5
0 0 -1
1 0 0
0 1 0
0 0 0
0 0 1
$EndNodes
$Elements
2 3 1 3
2 1 2 1
1 2 3 4
3 1 4 2
2 1 2 3 4
3 5 2 3 4
$EndElements
)";

const char* kVtu = R"(<?xml version="1.0"?>
<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian">
  <UnstructuredGrid>
    <Piece NumberOfPoints="5" NumberOfCells="3">
      <Points>
        <DataArray type="Float64" NumberOfComponents="3" format="ascii">
          0 0 -1  1 0 0  0 1 0  0 0 0  0 0 1
        </DataArray>
      </Points>
      <Cells>
        <DataArray type="Int64" Name="connectivity" format="ascii">1 2 3 0 1 2 3 4 1 2 3</DataArray>
        <DataArray type="Int64" Name="offsets" format="ascii">4 8 11</DataArray>
        <DataArray type="UInt8" Name="types" format="ascii">10 10 5</DataArray>
      </Cells>
    </Piece>
  </UnstructuredGrid>
</VTKFile>
)";

double volume(const sim::TetMesh& m) {
    double v = 0;
    for (const sim::Tet& t : m.tets()) {
        const auto& p = m.positions();
        const double s = (p[size_t(t[1])] - p[size_t(t[0])])
                             .cross(p[size_t(t[2])] - p[size_t(t[0])])
                             .dot(p[size_t(t[3])] - p[size_t(t[0])]) /
                         6;
        EXPECT_GT(s, 0) << "every tetrahedron positive";
        v += s;
    }
    return v;
}

std::string refusal(const std::function<void()>& f) {
    try {
        f();
    } catch (const InputError& e) {
        return e.what();
    }
    return "(accepted)";
}

TEST(TetImport, TheSameMeshFromEachFormatScaledAndPositive) {
    const auto a = sim::parseGmshTets(kMsh22, "organ.msh", 0.01);
    const auto b = sim::parseGmshTets(kMsh41, "organ41.msh", 0.01);
    const auto c = sim::parseVtuTets(kVtu, "organ.vtu", 0.01);
    for (const auto* m : {a.get(), b.get(), c.get()}) {
        EXPECT_EQ(m->tets().size(), 2u);
        EXPECT_EQ(m->vertexCount(), 5u) << "the unused geometry point is dropped";
        EXPECT_NEAR(volume(*m), 2 * 1e-6 / 6, 1e-15) << "two tetrahedra of 1/6 cm³ each, in m³";
        double maxAbs = 0;
        for (const auto& p : m->positions())
            maxAbs = std::max(maxAbs, p.cwiseAbs().maxCoeff());
        EXPECT_DOUBLE_EQ(maxAbs, 0.01) << "centimetres to metres";
    }
}

TEST(TetImport, MalformedFilesAreRefusedNamingTheFileTheLineAndTheRule) {
    std::string s = kMsh22;
    s.replace(s.find("2.2 0 8"), 7, "2.2 1 8");
    EXPECT_THAT(refusal([&] { sim::parseGmshTets(s, "bin.msh"); }),
                HasSubstr("bin.msh: line 2: a binary .msh is not read"));
    s = kMsh22;
    s.replace(s.find("4 4 2 1 1 5 2 3 4"), 17, "4 11 2 1 1 5 2 3 4 1 1 1 1 1 1");
    EXPECT_THAT(refusal([&] { sim::parseGmshTets(s, "quad.msh"); }),
                HasSubstr("quad.msh: line 22: element 4 is of type 11 (10-node tetrahedron): only linear tetrahedra"));
    s = kMsh22;
    s.replace(s.find("5 0 0 1"), 7, "5 0 nan 1");
    EXPECT_THAT(refusal([&] { sim::parseGmshTets(s, "nan.msh"); }), HasSubstr("nan.msh: line 14:"));
    s = kMsh22;
    s.replace(s.find("1 2 3 4\n4"), 7, "1 2 3 7");
    EXPECT_THAT(refusal([&] { sim::parseGmshTets(s, "gap.msh"); }),
                HasSubstr("uses node 7, which the file does not define"));
    s = kMsh22;
    s.erase(s.find("$EndElements"));
    EXPECT_THAT(refusal([&] { sim::parseGmshTets(s, "cut.msh"); }), HasSubstr("cut.msh: unexpected end of file"));
    EXPECT_THAT(refusal([&] { sim::parseGmshTets("$MeshFormat\n3.0 0 8\n", "old.msh"); }),
                HasSubstr("MSH version 3.0 is not read"));
    EXPECT_THAT(refusal([&] { sim::parseGmshTets("", "empty.msh"); }), HasSubstr("empty.msh: unexpected end of file"));
    s = kMsh22;
    s.replace(s.find("5 0 0 1"), 7, "5 0.5 0.5 0"); // node 5 in the plane of 2, 3, 4: a flat tetrahedron
    EXPECT_THAT(refusal([&] { sim::parseGmshTets(s, "flat.msh"); }),
                HasSubstr("flat.msh: tetrahedron 1 (nodes 5 2 3 4) has no volume"));
    s = kMsh22;
    s.replace(s.find("9 5 5 5"), 7, "4 5 5 5");
    EXPECT_THAT(refusal([&] { sim::parseGmshTets(s, "twice.msh"); }),
                HasSubstr("twice.msh: line 15: node 4 is defined twice"));
    s = kMsh22;
    s.replace(s.find("4 4 2 1 1 5 2 3 4"), 17, "4 33 2 1 1 5 2 3 4");
    EXPECT_THAT(refusal([&] { sim::parseGmshTets(s, "t28.msh"); }), HasSubstr("element 4 is of type 33"));
    s = kMsh22;
    s.replace(s.find("3 4 2 1 1 1 2 3 4"), 17, "3 4 9223372036854775806 1 2 3 4");
    EXPECT_THAT(refusal([&] { sim::parseGmshTets(s, "tags.msh"); }), HasSubstr("needs 4 node tags"));
    // a surface-only file has nothing to simulate
    s = kMsh22;
    s.replace(s.find("3 4 2 1 1 1 2 3 4"), 17, "3 2 2 1 1 1 2 3");
    s.replace(s.find("4 4 2 1 1 5 2 3 4"), 17, "4 2 2 1 1 5 2 3");
    EXPECT_THAT(refusal([&] { sim::parseGmshTets(s, "skin.msh"); }), HasSubstr("skin.msh: has no linear tetrahedra"));

    std::string v = kVtu;
    v.replace(v.find("Name=\"connectivity\" format=\"ascii\""), 34, "Name=\"connectivity\" format=\"binary\"");
    EXPECT_THAT(refusal([&] { sim::parseVtuTets(v, "b.vtu"); }),
                HasSubstr("b.vtu: Cells/connectivity: DataArray is format=\"binary\": only ascii data is read"));
    v = kVtu;
    v.replace(v.find("10 10 5"), 7, "10 12 5");
    EXPECT_THAT(refusal([&] { sim::parseVtuTets(v, "hex.vtu"); }), HasSubstr("cell 1 is of VTK type 12"));
    v = kVtu;
    v.replace(v.find("4 8 11"), 6, "4 9 11");
    EXPECT_THAT(refusal([&] { sim::parseVtuTets(v, "off.vtu"); }), HasSubstr("tetrahedron with 5 points"));
    v = kVtu;
    v.replace(v.find("0 0 1\n"), 5, "0 0 x");
    EXPECT_THAT(refusal([&] { sim::parseVtuTets(v, "x.vtu"); }),
                HasSubstr("x.vtu: Points: value 14 'x' is not a valid number"));
    EXPECT_THAT(refusal([&] { sim::parseVtuTets("<html></html>", "page.vtu"); }), HasSubstr("is not a VTK XML file"));
    v = kVtu;
    v.replace(v.find("4 8 11"), 6, "4 8 10");
    EXPECT_THAT(refusal([&] { sim::parseVtuTets(v, "short.vtu"); }),
                HasSubstr("the last offset (10) is not the connectivity's length (11)"));
    v = kVtu;
    v.replace(v.find("</UnstructuredGrid>"), 0, "<Piece NumberOfPoints=\"0\" NumberOfCells=\"0\"></Piece>");
    EXPECT_THAT(refusal([&] { sim::parseVtuTets(v, "two.vtu"); }), HasSubstr("two.vtu: has 2 <Piece> elements"));
}

TEST(TetImport, ReadTetFileGoesByTheExtension) {
    const auto dir = std::filesystem::temp_directory_path() / "viscera-tet-import";
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "Organ.MSH") << kMsh22;
    std::ofstream(dir / "organ.vtu") << kVtu;
    EXPECT_TRUE(sim::isTetFile(dir / "Organ.MSH"));
    EXPECT_FALSE(sim::isTetFile(dir / "organ.obj"));
    EXPECT_EQ(sim::readTetFile(dir / "Organ.MSH", 0.01)->tets().size(), 2u);
    EXPECT_EQ(sim::readTetFile(dir / "organ.vtu")->tets().size(), 2u);
    EXPECT_THAT(refusal([&] { sim::readTetFile(dir / "organ.obj"); }),
                HasSubstr("organ.obj: is not a tetrahedral mesh file"));
    EXPECT_THAT(refusal([&] { sim::readTetFile(dir / "Organ.MSH", -1); }),
                HasSubstr("scale must be a positive number"));
    std::filesystem::remove_all(dir);
}

} // namespace
