// Surface import: accepted formats, the extension/content whitelist and the input rules.
// Every fixture is written to a temporary folder at run time (no binary files in the tree).
#include "bake/import.hpp"
#include "bake/references.hpp"

#include "sim/mesh/generators.hpp"
#include "sim/util/error.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <bit>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <random>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace fs = std::filesystem;
using namespace viscera;
using ::testing::AllOf;
using ::testing::HasSubstr;

namespace {

// ---- byte and text writers -----------------------------------------------------------------

void putU32(std::string& out, uint32_t v) {
    for (int i = 0; i < 4; ++i)
        out.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}
void putU16(std::string& out, uint16_t v) {
    out.push_back(static_cast<char>(v & 0xff));
    out.push_back(static_cast<char>(v >> 8));
}
void putF32(std::string& out, float v) {
    putU32(out, std::bit_cast<uint32_t>(v));
}
void putU32be(std::string& out, uint32_t v) {
    for (int i = 3; i >= 0; --i)
        out.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}
void putF32be(std::string& out, float v) {
    putU32be(out, std::bit_cast<uint32_t>(v));
}

std::string num(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.9g", v);
    return buf;
}

std::string base64(std::string_view in) {
    static constexpr char tbl[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    size_t i = 0;
    for (; i + 2 < in.size(); i += 3) {
        const uint32_t n = (uint8_t(in[i]) << 16) | (uint8_t(in[i + 1]) << 8) | uint8_t(in[i + 2]);
        for (int k = 3; k >= 0; --k)
            out.push_back(tbl[(n >> (6 * k)) & 63]);
    }
    if (i + 1 == in.size()) {
        const uint32_t n = uint8_t(in[i]) << 16;
        out += {tbl[(n >> 18) & 63], tbl[(n >> 12) & 63], '=', '='};
    } else if (i + 2 == in.size()) {
        const uint32_t n = (uint8_t(in[i]) << 16) | (uint8_t(in[i + 1]) << 8);
        out += {tbl[(n >> 18) & 63], tbl[(n >> 12) & 63], tbl[(n >> 6) & 63], '='};
    }
    return out;
}

const sim::TriMesh& unitCube() {
    static const sim::TriMesh cube = sim::makeBoxSurface(sim::Vec3(0, 0, 0), sim::Vec3(1, 1, 1));
    return cube;
}

/// Unit cube with quads, split into two material groups (two assimp meshes sharing corners).
std::string cubeObj() {
    std::string s = "# unit cube\nmtllib none.mtl\n";
    for (int k = 0; k < 8; ++k)
        s += "v " + std::to_string(k & 1) + " " + std::to_string((k >> 1) & 1) + " " + std::to_string((k >> 2) & 1) +
             "\n";
    s += "vt 0 0\nvn 0 0 1\n";
    s += "usemtl a\nf 1 3 4 2\nf 5/1 6/1 8/1 7/1\nf 1//1 2//1 6//1 5//1\n";
    s += "usemtl b\nf 3/1/1 7/1/1 8/1/1 4/1/1\nf -8 -4 -2 -6\nf 2 4 8 6\n";
    return s;
}

std::string stlAscii(const sim::TriMesh& m) {
    std::string s = "solid shape\n";
    for (size_t t = 0; t < m.triangleCount(); ++t) {
        const sim::Vec3 n = m.triangleNormal(t);
        s += "  facet normal " + num(n.x()) + " " + num(n.y()) + " " + num(n.z()) + "\n    outer loop\n";
        for (int32_t v : m.triangles()[t]) {
            const sim::Vec3& p = m.positions()[v];
            s += "      vertex " + num(p.x()) + " " + num(p.y()) + " " + num(p.z()) + "\n";
        }
        s += "    endloop\n  endfacet\n";
    }
    return s + "endsolid shape\n";
}

std::string stlBinary(const sim::TriMesh& m, std::string_view header = "viscera test") {
    std::string s(header);
    s.resize(80, '\0');
    putU32(s, static_cast<uint32_t>(m.triangleCount()));
    for (size_t t = 0; t < m.triangleCount(); ++t) {
        const sim::Vec3 n = m.triangleNormal(t);
        for (int k = 0; k < 3; ++k)
            putF32(s, static_cast<float>(n[k]));
        for (int32_t v : m.triangles()[t])
            for (int k = 0; k < 3; ++k)
                putF32(s, static_cast<float>(m.positions()[v][k]));
        putU16(s, 0);
    }
    return s;
}

enum class PlyEnc { Ascii, LittleEndian, BigEndian };

std::string ply(const sim::TriMesh& m, PlyEnc enc) {
    const char* names[] = {"ascii", "binary_little_endian", "binary_big_endian"};
    std::string s = "ply\nformat " + std::string(names[static_cast<int>(enc)]) +
                    " 1.0\ncomment viscera test\nelement vertex " + std::to_string(m.vertexCount()) +
                    "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
                    std::to_string(m.triangleCount()) + "\nproperty list uchar int vertex_indices\nend_header\n";
    for (const sim::Vec3& p : m.positions()) {
        if (enc == PlyEnc::Ascii) s += num(p.x()) + " " + num(p.y()) + " " + num(p.z()) + "\n";
        for (int k = 0; k < 3 && enc != PlyEnc::Ascii; ++k)
            enc == PlyEnc::BigEndian ? putF32be(s, static_cast<float>(p[k])) : putF32(s, static_cast<float>(p[k]));
    }
    for (const sim::Tri& t : m.triangles()) {
        if (enc == PlyEnc::Ascii) {
            s += "3 " + std::to_string(t[0]) + " " + std::to_string(t[1]) + " " + std::to_string(t[2]) + "\n";
            continue;
        }
        s.push_back(3);
        for (int32_t v : t)
            enc == PlyEnc::BigEndian ? putU32be(s, static_cast<uint32_t>(v)) : putU32(s, static_cast<uint32_t>(v));
    }
    return s;
}

/// Positions (float32 VEC3) followed by uint16 indices, padded to 4 bytes.
std::string gltfBuffer(const sim::TriMesh& m) {
    std::string b;
    for (const sim::Vec3& p : m.positions())
        for (int k = 0; k < 3; ++k)
            putF32(b, static_cast<float>(p[k]));
    for (const sim::Tri& t : m.triangles())
        for (int32_t v : t)
            putU16(b, static_cast<uint16_t>(v));
    while (b.size() % 4)
        b.push_back('\0');
    return b;
}

/// glTF 2.0 document; `nodes` is the JSON array of nodes, all referring to mesh 0.
std::string gltfJson(const sim::TriMesh& m, const std::string& bufferUri, const std::string& nodes = R"([{"mesh":0}])",
                     const std::string& scene = "[0]") {
    const size_t posBytes = 12 * m.vertexCount();
    const size_t idxBytes = 6 * m.triangleCount();
    const size_t total = gltfBuffer(m).size();
    std::string buffer = R"({"byteLength":)" + std::to_string(total);
    if (!bufferUri.empty()) buffer += R"(,"uri":")" + bufferUri + "\"";
    buffer += "}";
    return R"({"asset":{"version":"2.0","generator":"viscera test"},"scene":0,)"
           R"("scenes":[{"nodes":)" +
           scene + R"(}],"nodes":)" + nodes +
           R"(,"meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],)"
           R"("buffers":[)" +
           buffer + R"(],"bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":)" + std::to_string(posBytes) +
           R"(},{"buffer":0,"byteOffset":)" + std::to_string(posBytes) + R"(,"byteLength":)" +
           std::to_string(idxBytes) + R"(}],"accessors":[{"bufferView":0,"componentType":5126,"count":)" +
           std::to_string(m.vertexCount()) +
           R"(,"type":"VEC3","min":[0,0,0],"max":[1,1,1]},{"bufferView":1,"componentType":5123,"count":)" +
           std::to_string(3 * m.triangleCount()) + R"(,"type":"SCALAR"}]})";
}

std::string gltf(const sim::TriMesh& m, const std::string& nodes = R"([{"mesh":0}])",
                 const std::string& scene = "[0]") {
    return gltfJson(m, "data:application/octet-stream;base64," + base64(gltfBuffer(m)), nodes, scene);
}

std::string glb(const sim::TriMesh& m) {
    std::string json = gltfJson(m, "");
    while (json.size() % 4)
        json.push_back(' ');
    const std::string bin = gltfBuffer(m);
    std::string s = "glTF";
    putU32(s, 2);
    putU32(s, static_cast<uint32_t>(12 + 8 + json.size() + 8 + bin.size()));
    putU32(s, static_cast<uint32_t>(json.size()));
    s += "JSON" + json;
    putU32(s, static_cast<uint32_t>(bin.size()));
    s += std::string("BIN\0", 4) + bin;
    return s;
}

/// Minimal ASCII FBX 7.4 with one tetrahedron (the last index of a polygon is stored as -i-1).
std::string fbxTetrahedron() {
    return "; FBX 7.4.0 project file\n"
           "FBXHeaderExtension:  {\n\tFBXHeaderVersion: 1003\n\tFBXVersion: 7400\n}\n"
           "Objects:  {\n"
           "\tGeometry: 1000, \"Geometry::tet\", \"Mesh\" {\n"
           "\t\tVertices: *12 {\n\t\t\ta: 0,0,0,1,0,0,0,1,0,0,0,1\n\t\t}\n"
           "\t\tPolygonVertexIndex: *12 {\n\t\t\ta: 0,2,-2,0,1,-4,0,3,-3,1,2,-4\n\t\t}\n"
           "\t\tGeometryVersion: 124\n\t}\n"
           "\tModel: 2000, \"Model::tet\", \"Mesh\" {\n\t\tVersion: 232\n\t}\n"
           "}\n"
           "Connections:  {\n\tC: \"OO\",2000,0\n\tC: \"OO\",1000,2000\n}\n";
}

// ---- fixture -------------------------------------------------------------------------------

class ImportTest : public ::testing::Test {
protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        m_dir = fs::path(::testing::TempDir()) /
                ("viscera_bake_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
        fs::remove_all(m_dir);
        fs::create_directories(m_dir);
    }
    void TearDown() override { fs::remove_all(m_dir); }

    fs::path write(const std::string& name, std::string_view bytes) const {
        const fs::path p = m_dir / name;
        std::FILE* f = std::fopen(p.c_str(), "wb");
        EXPECT_NE(f, nullptr) << p;
        if (f) {
            std::fwrite(bytes.data(), 1, bytes.size(), f);
            std::fclose(f);
        }
        return p;
    }

    /// The message of the InputError thrown by importSurface(file); fails the test otherwise.
    static std::string importError(const fs::path& file, const bake::ImportOptions& opt = {}) {
        try {
            bake::importSurface(file, opt);
        } catch (const InputError& e) {
            return e.what();
        } catch (const std::exception& e) {
            ADD_FAILURE() << file << ": expected InputError, got: " << e.what();
            return {};
        }
        ADD_FAILURE() << file << ": expected InputError, the import succeeded";
        return {};
    }

    fs::path m_dir;
};
// Suites are named <folder>_<unit> so that `ctest -R bake` selects them.
using bake_import = ImportTest;

void expectUnitCube(const sim::TriMesh& m) {
    EXPECT_EQ(m.vertexCount(), 8u);
    EXPECT_EQ(m.triangleCount(), 12u);
    EXPECT_TRUE(m.isClosedOriented());
    EXPECT_NEAR(m.signedVolume(), 1.0, 1e-6);
}

} // namespace

// ---- accepted formats ----------------------------------------------------------------------

TEST_F(bake_import, ObjQuadsInTwoMaterialGroupsMergeIntoOneClosedSurface) {
    const bake::ImportResult r = bake::importSurfaceWithReport(write("cube.obj", cubeObj()));
    expectUnitCube(r.mesh);
    EXPECT_EQ(r.report.format, bake::SurfaceFormat::Obj);
    EXPECT_EQ(r.report.meshInstances, 2u);
    EXPECT_EQ(r.report.sourceTriangles, 12u);
    EXPECT_EQ(r.report.degenerateTrianglesDropped, 0u);
}

TEST_F(bake_import, ObjUnitScale) {
    bake::ImportOptions opt;
    opt.scale = 0.001; // millimetres
    const sim::TriMesh m = bake::importSurface(write("cube_mm.obj", cubeObj()), opt);
    EXPECT_NEAR(m.signedVolume(), 1e-9, 1e-15);
    EXPECT_NEAR(m.bounds()[1].x(), 0.001, 1e-12);
}

TEST_F(bake_import, AsciiStlWithFacetNormalsIsJoined) {
    const bake::ImportResult r = bake::importSurfaceWithReport(write("cube.stl", stlAscii(unitCube())));
    expectUnitCube(r.mesh);
    EXPECT_EQ(r.report.format, bake::SurfaceFormat::StlAscii);
}

TEST_F(bake_import, BinaryStl) {
    const bake::ImportResult r = bake::importSurfaceWithReport(write("cube.stl", stlBinary(unitCube())));
    expectUnitCube(r.mesh);
    EXPECT_EQ(r.report.format, bake::SurfaceFormat::StlBinary);
}

TEST_F(bake_import, BinaryStlWhoseHeaderStartsWithSolid) {
    const fs::path p = write("cube.STL", stlBinary(unitCube(), "solid exported by a CAD tool"));
    EXPECT_EQ(bake::detectSurfaceFormat(p), bake::SurfaceFormat::StlBinary);
    expectUnitCube(bake::importSurface(p));
}

TEST_F(bake_import, PlyAsciiAndBinaryBothEndians) {
    expectUnitCube(bake::importSurface(write("a.ply", ply(unitCube(), PlyEnc::Ascii))));
    expectUnitCube(bake::importSurface(write("le.ply", ply(unitCube(), PlyEnc::LittleEndian))));
    expectUnitCube(bake::importSurface(write("be.ply", ply(unitCube(), PlyEnc::BigEndian))));
}

TEST_F(bake_import, GltfWithEmbeddedBuffer) {
    const bake::ImportResult r = bake::importSurfaceWithReport(write("cube.gltf", gltf(unitCube())));
    expectUnitCube(r.mesh);
    EXPECT_EQ(r.report.format, bake::SurfaceFormat::Gltf);
}

TEST_F(bake_import, Glb) {
    const fs::path p = write("cube.glb", glb(unitCube()));
    EXPECT_EQ(bake::detectSurfaceFormat(p), bake::SurfaceFormat::Glb);
    expectUnitCube(bake::importSurface(p));
}

TEST_F(bake_import, AsciiFbx) {
    const bake::ImportResult r = bake::importSurfaceWithReport(write("tet.fbx", fbxTetrahedron()));
    EXPECT_EQ(r.mesh.vertexCount(), 4u);
    EXPECT_EQ(r.mesh.triangleCount(), 4u);
    EXPECT_TRUE(r.mesh.isClosedOriented());
    EXPECT_NEAR(std::abs(r.mesh.signedVolume()), 1.0 / 6.0, 1e-6);
    EXPECT_EQ(r.report.format, bake::SurfaceFormat::Fbx);
}

TEST_F(bake_import, NodeTransformsAndInstancesAreApplied) {
    // Two instances of the cube: one translated by 2 in x and scaled by 3, one mirrored in x.
    const std::string nodes = R"([{"children":[1,2]},{"mesh":0,"translation":[2,0,0],"scale":[3,3,3]},)"
                              R"({"mesh":0,"scale":[-1,1,1]}])";
    const bake::ImportResult r = bake::importSurfaceWithReport(write("two.gltf", gltf(unitCube(), nodes)));
    EXPECT_EQ(r.report.meshInstances, 2u);
    EXPECT_EQ(r.mesh.vertexCount(), 16u);
    EXPECT_EQ(r.mesh.triangleCount(), 24u);
    // Mirroring keeps the outward orientation: both volumes count positively.
    EXPECT_NEAR(r.mesh.signedVolume(), 27.0 + 1.0, 1e-4);
    EXPECT_TRUE(r.mesh.isClosedOriented());
    const auto [lo, hi] = r.mesh.bounds();
    EXPECT_NEAR(lo.x(), -1.0, 1e-6);
    EXPECT_NEAR(hi.x(), 5.0, 1e-6);
}

TEST_F(bake_import, CollapsedTrianglesAreDroppedAndReported) {
    std::string obj = cubeObj();
    obj += "v 1 1 1\nf 8 9 7\n"; // vertex 9 coincides with vertex 8: the triangle collapses
    const bake::ImportResult r = bake::importSurfaceWithReport(write("sliver.obj", obj));
    expectUnitCube(r.mesh);
    EXPECT_EQ(r.report.degenerateTrianglesDropped, 1u);
}

TEST_F(bake_import, AcceptedExtensions) {
    std::vector<std::string_view> ext(bake::acceptedExtensions().begin(), bake::acceptedExtensions().end());
    EXPECT_THAT(ext, ::testing::ElementsAre(".obj", ".stl", ".ply", ".gltf", ".glb", ".fbx"));
}

// ---- whitelist: extension and content ------------------------------------------------------

TEST_F(bake_import, UnknownExtensionIsRejectedBeforeReading) {
    const fs::path p = write("organ.xyz", cubeObj());
    EXPECT_THAT(importError(p), AllOf(HasSubstr(p.string()), HasSubstr("unsupported format '.xyz'"),
                                      HasSubstr("(accepted: .obj .stl .ply .gltf .glb .fbx)")));
    const fs::path noExt = write("organ", cubeObj());
    EXPECT_THAT(importError(noExt), HasSubstr("unsupported format (no extension)"));
    EXPECT_THAT(importError(write("scene.dae", "<COLLADA/>")), HasSubstr("unsupported format '.dae'"));
}

TEST_F(bake_import, ContentMustMatchTheExtension) {
    const fs::path plyAsStl = write("liver.stl", ply(unitCube(), PlyEnc::Ascii));
    EXPECT_THAT(importError(plyAsStl), AllOf(HasSubstr(plyAsStl.string()), HasSubstr("content does not look like STL"),
                                             HasSubstr("it looks like PLY")));
    const fs::path objAsGlb = write("liver.glb", cubeObj());
    EXPECT_THAT(importError(objAsGlb), AllOf(HasSubstr("content does not look like GLB"), HasSubstr("'glTF' magic")));
    const fs::path stlAsObj = write("liver.obj", stlBinary(unitCube()));
    EXPECT_THAT(importError(stlAsObj), AllOf(HasSubstr("content does not look like OBJ"), HasSubstr("NUL byte")));
    const fs::path jsonWithoutAsset = write("liver.gltf", R"({"scenes":[]})");
    EXPECT_THAT(importError(jsonWithoutAsset),
                AllOf(HasSubstr("content does not look like glTF"), HasSubstr("\"asset\"")));
    const fs::path objAsFbx = write("liver.fbx", cubeObj());
    EXPECT_THAT(importError(objAsFbx),
                AllOf(HasSubstr("content does not look like FBX"), HasSubstr("it looks like OBJ")));
    const fs::path textAsPly = write("liver.ply", "solid x\nendsolid x\n");
    EXPECT_THAT(importError(textAsPly), AllOf(HasSubstr("content does not look like PLY"), HasSubstr("'ply' magic")));
    const fs::path glbAsGltf = write("liver.gltf", glb(unitCube()));
    EXPECT_THAT(importError(glbAsGltf),
                AllOf(HasSubstr("content does not look like glTF"), HasSubstr("it looks like GLB")));
}

TEST_F(bake_import, EmptyFilesAreRejected) {
    for (const char* name : {"e.obj", "e.stl", "e.ply", "e.gltf", "e.glb", "e.fbx"}) {
        const fs::path p = write(name, "");
        EXPECT_THAT(importError(p), AllOf(HasSubstr(p.string()), HasSubstr("file is empty")));
    }
}

TEST_F(bake_import, RandomBytesAreRejected) {
    std::mt19937 rng(1234);
    for (const char* ext : {".obj", ".stl", ".ply", ".gltf", ".glb", ".fbx"}) {
        for (int k = 0; k < 5; ++k) {
            std::string bytes(200 + 37 * k, '\0');
            for (char& c : bytes)
                c = static_cast<char>(rng() & 0xff);
            bytes[k] = '\0'; // binary junk always holds a NUL somewhere
            const fs::path p = write("junk" + std::to_string(k) + ext, bytes);
            EXPECT_THAT(importError(p), AllOf(HasSubstr(p.string()), HasSubstr("content does not look like")));
        }
    }
}

TEST_F(bake_import, MissingFileAndDirectory) {
    EXPECT_THAT(importError(m_dir / "absent.obj"), AllOf(HasSubstr("absent.obj"), HasSubstr("file not found")));
    fs::create_directories(m_dir / "folder.obj");
    EXPECT_THAT(importError(m_dir / "folder.obj"), HasSubstr("is a directory"));
}

TEST_F(bake_import, FifoIsNotReadAsAMesh) {
    const fs::path fifo = m_dir / "pipe.obj";
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    EXPECT_EQ(importError(fifo), fifo.string() + ": is not a regular file"); // returns at once, no writer needed
}

TEST_F(bake_import, TooLargeFileIsRejectedBeforeParsing) {
    bake::ImportOptions opt;
    opt.maxFileBytes = 16;
    const fs::path p = write("big.obj", cubeObj());
    EXPECT_THAT(importError(p, opt), AllOf(HasSubstr(p.string()), HasSubstr("maxFileBytes")));
}

TEST_F(bake_import, InvalidScaleIsAPreconditionError) {
    const fs::path p = write("cube.obj", cubeObj());
    for (double s : {0.0, -1.0, std::numeric_limits<double>::quiet_NaN()}) {
        bake::ImportOptions opt;
        opt.scale = s;
        EXPECT_THROW(bake::importSurface(p, opt), std::invalid_argument);
    }
}

// ---- input rules ---------------------------------------------------------------------------

TEST_F(bake_import, NonFiniteCoordinatesNameTheVertex) {
    const fs::path obj = write("nan.obj", "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n");
    EXPECT_THAT(importError(obj), AllOf(HasSubstr(obj.string()), HasSubstr("line 3"),
                                        HasSubstr("vertex 3 has a non-finite coordinate (nan)")));
    const fs::path inf = write("inf.obj", "v 0 0 0\nv 1e999 0 0\nv 0 1 0\nf 1 2 3\n");
    EXPECT_THAT(importError(inf), HasSubstr("vertex 2 has a non-finite coordinate"));

    sim::TriMesh cube = unitCube();
    cube.positions()[5].y() = std::numeric_limits<double>::quiet_NaN();
    const fs::path stlB = write("nan.stl", stlBinary(cube));
    EXPECT_THAT(importError(stlB), AllOf(HasSubstr(stlB.string()), HasSubstr("non-finite")));
    const fs::path stlA = write("nan_ascii.stl", stlAscii(cube));
    EXPECT_THAT(importError(stlA), AllOf(HasSubstr(stlA.string()), HasSubstr("non-finite")));
    const fs::path plyA = write("nan.ply", ply(cube, PlyEnc::Ascii));
    EXPECT_THAT(importError(plyA), AllOf(HasSubstr(plyA.string()), HasSubstr("vertex 5 has a non-finite y")));
    const fs::path plyB = write("nan_bin.ply", ply(cube, PlyEnc::LittleEndian));
    EXPECT_THAT(importError(plyB), HasSubstr("vertex 5 has a non-finite y"));
    const fs::path gl = write("nan.gltf", gltf(cube));
    EXPECT_THAT(importError(gl), AllOf(HasSubstr(gl.string()), HasSubstr("vertex 5"), HasSubstr("non-finite")));
}

TEST_F(bake_import, NoFaces) {
    const fs::path obj = write("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\n");
    EXPECT_THAT(importError(obj), AllOf(HasSubstr(obj.string()), HasSubstr("no faces")));
    const fs::path plyNoFace = write("cloud.ply", "ply\nformat ascii 1.0\nelement vertex 1\n"
                                                  "property float x\nproperty float y\n"
                                                  "property float z\nend_header\n0 0 0\n");
    EXPECT_THAT(importError(plyNoFace), HasSubstr("no faces"));
    const fs::path stl0 = write("zero.stl", stlBinary(sim::TriMesh{}));
    EXPECT_THAT(importError(stl0), AllOf(HasSubstr(stl0.string()), HasSubstr("no faces")));
    const fs::path stlA = write("empty_solid.stl", "solid x\nendsolid x\n");
    EXPECT_THAT(importError(stlA), HasSubstr("no faces"));
    const fs::path gl = write("empty.gltf", R"({"asset":{"version":"2.0"},"scenes":[{"nodes":[]}],"scene":0})");
    EXPECT_THAT(importError(gl),
                AllOf(HasSubstr(gl.string()), ::testing::AnyOf(HasSubstr("empty scene"), HasSubstr("no faces"))));
}

TEST_F(bake_import, FaceIndexOutOfRangeNamesFaceAndIndex) {
    const std::string v3 = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    const fs::path big = write("oor.obj", v3 + "f 1 2 3\nf 1 2 9\n");
    EXPECT_THAT(importError(big), AllOf(HasSubstr(big.string()), HasSubstr("line 5: face 2"),
                                        HasSubstr("vertex index 9 is out of range (the file has 3 vertices)")));
    const fs::path zero = write("zero.obj", v3 + "f 1 2 0\n");
    EXPECT_THAT(importError(zero), HasSubstr("face 1: vertex index 0 is invalid (OBJ indices start at 1)"));
    const fs::path neg = write("neg.obj", v3 + "f -1 -2 -4\n");
    EXPECT_THAT(importError(neg), HasSubstr("face 1: vertex index -4 is out of range"));
    const fs::path tex = write("tex.obj", v3 + "vt 0 0\nf 1/1 2/1 3/2\n");
    EXPECT_THAT(importError(tex), HasSubstr("texture coordinate index 2 is out of range"));
    const fs::path nrm = write("nrm.obj", v3 + "f 1//1 2//1 3//1\n");
    EXPECT_THAT(importError(nrm), HasSubstr("normal index 1 is out of range"));
    const fs::path junk = write("junk.obj", v3 + "f 1 2 x\n");
    EXPECT_THAT(importError(junk), HasSubstr("face 1: cannot parse vertex index 'x'"));

    const fs::path plyBad = write("oor.ply", "ply\nformat ascii 1.0\nelement vertex 3\n"
                                             "property float x\nproperty float y\nproperty float z\n"
                                             "element face 1\nproperty list uchar int vertex_indices\n"
                                             "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n");
    EXPECT_THAT(importError(plyBad), AllOf(HasSubstr(plyBad.string()),
                                           HasSubstr("face 0: index 2 references vertex 7 (the file has 3 vertices)")));
}

TEST_F(bake_import, TruncatedAndMalformedPly) {
    const std::string good = ply(unitCube(), PlyEnc::LittleEndian);
    const fs::path cut = write("cut.ply", good.substr(0, good.size() - 7));
    EXPECT_THAT(importError(cut), AllOf(HasSubstr(cut.string()), HasSubstr("truncated")));
    std::string noEnd = ply(unitCube(), PlyEnc::Ascii);
    noEnd.replace(noEnd.find("end_header"), 10, "end_headex");
    EXPECT_THAT(importError(write("noend.ply", noEnd)), HasSubstr("unknown keyword 'end_headex'"));
    std::string badType = ply(unitCube(), PlyEnc::Ascii);
    badType.replace(badType.find("float y"), 5, "flo6t");
    EXPECT_THAT(importError(write("type.ply", badType)), HasSubstr("unknown property type 'flo6t'"));
}

TEST_F(bake_import, TruncatedGlbIsRejected) {
    const std::string good = glb(unitCube());
    const fs::path p = write("cut.glb", good.substr(0, good.size() - 10));
    EXPECT_THAT(importError(p), AllOf(HasSubstr(p.string()), HasSubstr("truncated")));
}

// Every prefix and a few hundred byte-flipped variants of each valid fixture either import or
// throw InputError: no crash, hang or other exception type.
TEST_F(bake_import, TruncatedAndCorruptedFilesNeverCrash) {
    const std::pair<std::string, std::string> fixtures[] = {
        {".obj", cubeObj()},
        {".stl", stlAscii(unitCube())},
        {".stl", stlBinary(unitCube())},
        {".ply", ply(unitCube(), PlyEnc::Ascii)},
        {".ply", ply(unitCube(), PlyEnc::LittleEndian)},
        {".gltf", gltf(unitCube())},
        {".glb", glb(unitCube())},
        {".fbx", fbxTetrahedron()},
    };
    std::mt19937 rng(99);
    int imported = 0, rejected = 0, index = 0;
    auto attempt = [&](const std::string& ext, const std::string& bytes) {
        const fs::path p = write("fuzz" + std::to_string(index++ % 8) + ext, bytes);
        try {
            bake::importSurface(p);
            ++imported;
        } catch (const InputError& e) {
            ++rejected;
            EXPECT_THAT(e.what(), HasSubstr(p.string()));
        } catch (const std::exception& e) {
            ADD_FAILURE() << "unexpected exception for a variant of " << ext << ": " << e.what();
        }
    };
    for (const auto& [ext, bytes] : fixtures) {
        const size_t step = std::max<size_t>(1, bytes.size() / 120);
        for (size_t n = 0; n < bytes.size(); n += step)
            attempt(ext, bytes.substr(0, n));
        for (int k = 0; k < 150; ++k) {
            std::string b = bytes;
            const int flips = 1 + static_cast<int>(rng() % 4);
            for (int f = 0; f < flips; ++f)
                b[rng() % b.size()] = static_cast<char>(rng() & 0xff);
            attempt(ext, b);
        }
    }
    EXPECT_GT(rejected, 0);
    EXPECT_GT(imported, 0);
}

// ---- references to other files [issue 16 item 3] -----------------------------------------------
// Each refused reference points at a file that exists and would import: were it followed, the
// import would succeed, so the refusal shows it was not.

namespace {

/// A folder layout: <dir>/outside/cube.bin (a valid buffer of the unit cube), <dir>/a/b/ for the
/// file under test.
struct Layout {
    fs::path outsideBin, inner;
};

Layout makeLayout(const fs::path& dir) {
    fs::create_directories(dir / "outside");
    fs::create_directories(dir / "a" / "b");
    const fs::path bin = dir / "outside" / "cube.bin";
    std::FILE* f = std::fopen(bin.c_str(), "wb");
    const std::string b = gltfBuffer(unitCube());
    std::fwrite(b.data(), 1, b.size(), f);
    std::fclose(f);
    return {bin, dir / "a" / "b"};
}

std::string glbWithJson(std::string json) {
    while (json.size() % 4)
        json.push_back(' ');
    std::string s = "glTF";
    putU32(s, 2);
    putU32(s, static_cast<uint32_t>(12 + 8 + json.size()));
    putU32(s, static_cast<uint32_t>(json.size()));
    return s + "JSON" + json;
}

} // namespace

TEST(bake_references, TheRuleAdmitsRelativePathsInsideTheFolderOnly) {
    using bake::detail::referenceProblem;
    for (const char* ok : {"cube.bin", "tex/skin diffuse.png", "x..y.png", "./a/b.mtl", "a/..b/c"})
        EXPECT_EQ(referenceProblem(ok), std::nullopt) << ok;
    const std::pair<const char*, const char*> refused[] = {
        {"", "empty reference"},
        {"../x", "'..' component"},
        {"a/../../x", "'..' component"},
        {"a\\..\\x", "'..' component"},
        {"..", "'..' component"},
        {"/etc/passwd", "absolute path"},
        {"\\\\server\\share\\x", "absolute path"},
        {"C:x.png", "drive letter"},
        {"c:\\x.png", "drive letter"},
        {"file:///etc/passwd", "URI scheme ('file:')"},
        {"http://example.com/x.bin", "URI scheme ('http:')"},
        {"x\x01.png", "control character"},
    };
    for (const auto& [path, rule] : refused) {
        const auto problem = referenceProblem(path);
        ASSERT_TRUE(problem.has_value()) << path;
        EXPECT_THAT(*problem, HasSubstr(rule)) << path;
    }
}

TEST_F(bake_import, AGltfBufferInItsFolderIsRead) {
    const Layout l = makeLayout(m_dir);
    fs::copy_file(l.outsideBin, l.inner / "cube.bin");
    expectUnitCube(bake::importSurface(write("a/b/cube.gltf", gltfJson(unitCube(), "cube.bin"))));
}

TEST_F(bake_import, GltfReferencesOutOfTheFolderAreRefusedUnread) {
    const Layout l = makeLayout(m_dir);
    const std::pair<std::string, std::string> cases[] = {
        {"../../outside/cube.bin",
         "buffers[0].uri '../../outside/cube.bin': leaves the file's folder ('..' component)"},
        {l.outsideBin.string(), "buffers[0].uri '" + l.outsideBin.string() + "': absolute path"},
        {"file://" + l.outsideBin.string(), "a URI scheme ('file:') is refused"},
        {"%2E%2E/%2e%2e/outside/cube.bin", "buffers[0].uri '../../outside/cube.bin': leaves the file's folder"},
    };
    int k = 0;
    for (const auto& [uri, message] : cases) {
        const fs::path p = write("a/b/cube" + std::to_string(k++) + ".gltf", gltfJson(unitCube(), uri));
        const std::string e = importError(p);
        EXPECT_THAT(e, AllOf(HasSubstr(p.string() + ": "), HasSubstr(message),
                             HasSubstr("references must be relative paths inside the file's folder")))
            << uri;
        EXPECT_EQ(e.find('\n'), std::string::npos) << e;
    }
}

TEST_F(bake_import, GlbAndGltfImageReferencesAreCheckedToo) {
    const std::string json = R"({"asset":{"version":"2.0"},"images":[{"uri":"data:image/png;base64,AAAA"},)"
                             R"({"uri":"../secret.png"}],"buffers":[{"byteLength":4}]})";
    EXPECT_THAT(importError(write("img.glb", glbWithJson(json))),
                HasSubstr("images[1].uri '../secret.png': leaves the file's folder"));
    EXPECT_THAT(importError(write("img.gltf", json)), HasSubstr("images[1].uri '../secret.png'"));
    // A glTF 1.0 shader (or any extension) naming a file is a reference as well.
    EXPECT_THAT(importError(write("v1.gltf", R"({"asset":{"version":"1.0"},"shaders":{"vs":{"uri":"/etc/x"}}})")),
                HasSubstr("shaders.vs.uri '/etc/x': absolute path"));
}

TEST_F(bake_import, ObjMaterialLibrariesAndTheirTexturesMustStayInTheFolder) {
    makeLayout(m_dir);
    write("a/x.mtl", "newmtl skin\nKd 1 0 0\n");
    const fs::path obj = write("a/b/cube.obj", "mtllib ../x.mtl\n" + cubeObj());
    EXPECT_THAT(importError(obj), HasSubstr(obj.string() + ": line 1: mtllib '../x.mtl': leaves the file's folder"));
    // Two names on one line: each is checked.
    EXPECT_THAT(importError(write("a/b/two.obj", "mtllib ok.mtl /etc/x.mtl\n" + cubeObj())),
                HasSubstr("mtllib '/etc/x.mtl': absolute path"));
    // A library inside the folder is read, and its textures are checked (options before the name).
    write("a/b/cube.mtl", "newmtl skin\nKd 1 0 0\nmap_Kd -bm 1.0 ../../outside/skin.png\n");
    const fs::path inner = write("a/b/inner.obj", "mtllib cube.mtl\n" + cubeObj());
    EXPECT_THAT(importError(inner),
                HasSubstr("cube.mtl line 3: map_Kd '../../outside/skin.png': leaves the file's folder"));
    write("a/b/cube.mtl", "newmtl skin\nKd 1 0 0\nmap_Kd textures/skin.png\n");
    expectUnitCube(bake::importSurface(inner));
}

TEST_F(bake_import, ALinkOutOfTheFolderIsNotFollowed) {
    const Layout l = makeLayout(m_dir);
    fs::create_symlink(l.outsideBin, l.inner / "link.bin");
    const fs::path p = write("a/b/linked.gltf", gltfJson(unitCube(), "link.bin"));
    EXPECT_THAT(importError(p), AllOf(HasSubstr(p.string() + ": the importer asked for '"),
                                      HasSubstr("link.bin', refused: outside the file's folder")));
}

TEST_F(bake_import, TheVertexAndTriangleCapsNameThemselves) {
    const fs::path p = write("cube.stl", stlBinary(unitCube()));
    bake::ImportOptions few;
    few.maxTriangles = 11;
    EXPECT_THAT(importError(p, few), AllOf(HasSubstr(p.string() + ": more than 11 triangles"),
                                           HasSubstr("over the import cap ImportOptions::maxTriangles")));
    few = {};
    few.maxVertices = 7;
    EXPECT_THAT(importError(p, few), HasSubstr("more than 7 vertices"));
    few.maxVertices = 8;
    expectUnitCube(bake::importSurface(p, few));
}

// Found in review: what assimp would read differently from a naive line or URI scan.
TEST_F(bake_import, ReferencesAreReadTheWayTheImporterReadsThem) {
    makeLayout(m_dir);
    write("a/x.mtl", "newmtl skin\n");
    // CR and FF end a line for assimp, '#' only starts a comment at a line's start, a final
    // backslash joins the next line.
    for (const std::string& head :
         {std::string("#\rmtllib ../x.mtl\n"), std::string("v 0 0 0\fmtllib ../x.mtl\n"),
          std::string("mtllib ok\\\n/../x.mtl\n"), std::string("mtllib x.mtl # ../x.mtl\n")}) {
        const fs::path p = write("a/b/cr.obj", head + cubeObj());
        EXPECT_THAT(importError(p), HasSubstr("leaves the file's folder")) << head;
    }
    // "DATA:" is no data URI to assimp (it matches case-sensitively), and a leading blank is
    // stripped by assimp's path cleanup.
    EXPECT_THAT(importError(write("a/b/d.gltf", gltfJson(unitCube(), "DATA:x/../../outside/cube.bin"))),
                HasSubstr("a URI scheme ('DATA:') is refused"));
    EXPECT_THAT(importError(write("a/b/s.gltf", gltfJson(unitCube(), " ../../outside/cube.bin"))),
                HasSubstr("begins or ends with a blank"));
    // Nesting that would overflow the recursive JSON parser of the importer.
    std::string deep = R"({"asset":{"version":"2.0"},"extras":)";
    deep += std::string(100, '[') + std::string(100, ']') + "}";
    EXPECT_THAT(importError(write("a/b/deep.gltf", deep)), HasSubstr("JSON nested more than 64 levels deep"));
}

TEST_F(bake_import, AMeshFileReachedThroughALinkImports) {
    const Layout l = makeLayout(m_dir);
    const fs::path real = write("outside/cube.obj", cubeObj());
    fs::create_symlink(real, l.inner / "linked.obj");
    expectUnitCube(bake::importSurface(l.inner / "linked.obj"));
}
