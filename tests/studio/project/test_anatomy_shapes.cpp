// Anatomy made by code (studio/project/anatomy_shapes.hpp): the bend keeps lengths along the
// sheet's top and never inverts a tet, refuses a node below its axis naming the field; the
// scenery generators give the surfaces asked for; bad scenery names the field and rule; a bent sheet
// of fat (the rectum sample as it was before its anatomy was imported, tests/studio/project/data)
// exports with its primitive scenery; the shipped rectum exports its imported anatomy.
#include "case/case_package.hpp"
#include "project/anatomy_shapes.hpp"
#include "project/project.hpp"
#include "sim/mesh/generators.hpp"
#include "sim/mesh/tet_io.hpp"
#include "sim/scene/scene.hpp"
#include "sim/util/error.hpp"
#include "support/scratch_dir.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>

using namespace viscera;
using sim::Vec3;
using ::testing::HasSubstr;

namespace {

/// projects/rectum: the textures and tracks the bent sheet's text names.
std::filesystem::path rectumDir() {
    return std::filesystem::path(VISCERA_SOURCE_DIR) / "projects" / "rectum";
}

/// The rectum sample's project as it was with a bent box of fat and primitive scenery.
std::string bentSheetText() {
    std::string text;
    const std::filesystem::path file =
        std::filesystem::path(VISCERA_SOURCE_DIR) / "tests/studio/project/data/bent_sheet_project.json";
    if (std::FILE* f = std::fopen(file.c_str(), "rb")) {
        char buf[4096];
        size_t n;
        while ((n = std::fread(buf, 1, sizeof buf, f)) > 0)
            text.append(buf, n);
        std::fclose(f);
    }
    return text;
}

} // namespace

TEST(AnatomyShapes, TheBendKeepsLengthsAlongTheTopAndInvertsNoTet) {
    const studio::BendSpec bend{0.032, 0.01};
    // Along the top (z = 0), arc length is the flat length; through the thickness, lengths too.
    const Vec3 a = studio::bendPoint(bend, Vec3(0, 0.01, 0)), b = studio::bendPoint(bend, Vec3(0, 0.01 + 1e-5, 0));
    EXPECT_NEAR((b - a).norm(), 1e-5, 1e-10);
    EXPECT_LT((a - Vec3(0, 0.01, 0)).norm(), 1e-15) << "the apex stays where it is";
    const Vec3 c = studio::bendPoint(bend, Vec3(0, 0.03, -0.004)), d = studio::bendPoint(bend, Vec3(0, 0.03, -0.005));
    EXPECT_NEAR((d - c).norm(), 1e-3, 1e-12);
    EXPECT_NEAR((studio::bendPoint(bend, Vec3(0.02, 0.05, -0.008)) - Vec3(0.02, 0.01, -0.032)).norm(), 0.024, 1e-12)
        << "the bottom of an 8 mm sheet lies 24 mm from the axis";
    // The rectum sample's fat sheet, bent: every tet keeps its orientation.
    sim::BoxSpec box;
    box.origin = Vec3(-0.06, -0.05, -0.008);
    box.size = Vec3(0.12, 0.1, 0.008);
    box.cells = {30, 25, 2};
    auto mesh = sim::makeBoxTetMesh(box);
    std::vector<Vec3> pos = mesh->positions();
    studio::bendPoints(bend, pos);
    auto bent = sim::TetMesh::fromArrays(pos, mesh->tets(), "bent");
    const auto q = bent->quality();
    EXPECT_TRUE(q.inverted.empty());
    EXPECT_TRUE(q.degenerate.empty());
    std::printf("bent sheet: %zu tets, min dihedral %.2f deg (flat %.2f)\n", bent->tetCount(), q.minDihedralDeg,
                mesh->quality().minDihedralDeg);
    // Deeper than the axis: refused with the node.
    std::vector<Vec3> deep = {Vec3(0, 0, -0.01), Vec3(0, 0, -0.05)};
    try {
        studio::bendPoints(bend, deep);
        FAIL() << "bent a node past the axis";
    } catch (const std::invalid_argument& e) {
        EXPECT_THAT(e.what(), HasSubstr("node 1 lies 0.05"));
    }
}

TEST(AnatomyShapes, SceneryGeneratorsGiveTheSurfacesAskedFor) {
    studio::SceneryProject cyl;
    cyl.name = "pelvic_wall";
    cyl.start = Vec3(-0.1, 0, 0);
    cyl.end = Vec3(0.1, 0, 0);
    cyl.radius = 0.075;
    cyl.fromDeg = 60;
    cyl.toDeg = 300;
    cyl.slices = 24;
    cyl.rings = 4;
    const sim::TriMesh wall = studio::scenerySurface(cyl);
    EXPECT_EQ(wall.vertexCount(), size_t(25 * 5));
    EXPECT_EQ(wall.triangleCount(), size_t(2 * 24 * 4));
    double minZ = 1, maxZ = -1;
    for (const Vec3& p : wall.positions()) {
        EXPECT_NEAR(std::hypot(p.y(), p.z()), 0.075, 1e-12);
        minZ = std::min(minZ, p.z());
        maxZ = std::max(maxZ, p.z());
    }
    EXPECT_NEAR(minZ, -0.075, 1e-12) << "through the bottom (180°)";
    EXPECT_NEAR(maxZ, 0.075 * std::cos(60 * M_PI / 180), 1e-12) << "open above 60°";
    // Which way the triangles face: towards the axis (a wall seen from inside) or away (an organ).
    auto facesAxis = [](const sim::TriMesh& m) {
        int towards = 0;
        for (const sim::Tri& t : m.triangles()) {
            const Vec3 &a = m.positions()[t[0]], &b = m.positions()[t[1]], &c = m.positions()[t[2]];
            const Vec3 n = (b - a).cross(c - a), centre = (a + b + c) / 3.0;
            if (n.dot(Vec3(0, -centre.y(), -centre.z())) > 0) ++towards;
        }
        return towards;
    };
    EXPECT_EQ(facesAxis(wall), int(wall.triangleCount())) << "inward by default";
    cyl.fromDeg = 0;
    cyl.toDeg = 360;
    EXPECT_EQ(studio::scenerySurface(cyl).vertexCount(), size_t(24 * 5)) << "a whole turn closes on itself";
    cyl.inward = false;
    EXPECT_EQ(facesAxis(studio::scenerySurface(cyl)), 0) << "outward: every triangle faces away";
    studio::SceneryProject disc;
    disc.name = "peritoneum";
    disc.generator = studio::SceneryProject::Generator::Disc;
    disc.center = Vec3(0.11, 0, 0);
    disc.normal = Vec3(-2, 0, 0);
    disc.radius = 0.05;
    disc.slices = 16;
    disc.rings = 3;
    const sim::TriMesh d = studio::scenerySurface(disc);
    EXPECT_EQ(d.vertexCount(), size_t(1 + 16 * 3));
    EXPECT_EQ(d.triangleCount(), size_t(16 + 2 * 16 * 2));
    for (const sim::Tri& t : d.triangles()) { // facing its normal (−x)
        const Vec3 &a = d.positions()[t[0]], &b = d.positions()[t[1]], &c = d.positions()[t[2]];
        EXPECT_LT((b - a).cross(c - a).x(), 0.0);
    }
    for (const Vec3& p : d.positions()) {
        EXPECT_NEAR(p.x(), 0.11, 1e-15);
        EXPECT_LE(std::hypot(p.y(), p.z()), 0.05 + 1e-12);
    }
}

TEST(AnatomyShapes, BadSceneryAndBendNameTheFieldAndRule) {
    const std::filesystem::path src = rectumDir();
    const std::string text = bentSheetText();
    ASSERT_FALSE(text.empty());
    auto error = [&](const std::string& from, const std::string& to) {
        std::string t = text;
        const size_t at = t.find(from);
        EXPECT_NE(at, std::string::npos) << from;
        if (at == std::string::npos) return std::string("not found");
        t.replace(at, from.size(), to);
        try {
            studio::loadProjectText(t, src, "project.json");
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return std::string("accepted");
    };
    EXPECT_THAT(
        error("\"generator\": \"disc\"", "\"generator\": \"cone\""),
        HasSubstr("project.json: scenery[2].generator: 'cone' is not a scenery generator (cylinder, disc, file)"));
    // an imported surrounding: its file inside the project folder, a positive scale, no primitive keys
    auto fileEntryError = [&](const nlohmann::json& entry) {
        nlohmann::json doc = nlohmann::json::parse(text);
        doc["scenery"][2] = entry;
        try {
            studio::loadProjectText(doc.dump(), src, "project.json");
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return std::string("accepted");
    };
    EXPECT_THAT(fileEntryError({{"name", "peritoneum"}, {"generator", "file"}, {"file", "../outside.obj"}}),
                HasSubstr("project.json: scenery[2].file:"));
    EXPECT_THAT(
        fileEntryError({{"name", "peritoneum"}, {"generator", "file"}, {"file", "anatomy/liver.obj"}, {"scale", 0}}),
        HasSubstr("project.json: scenery[2].scale: must be in (0, 1000]"));
    EXPECT_THAT(
        fileEntryError({{"name", "peritoneum"}, {"generator", "file"}, {"file", "anatomy/liver.obj"}, {"radius", 1}}),
        HasSubstr("project.json: scenery[2].radius: unknown field"));
    EXPECT_THAT(error("\"from_deg\": 55, \"to_deg\": 305", "\"from_deg\": 55, \"to_deg\": 500"),
                HasSubstr("project.json: scenery[1].to_deg: must be in [-360, 360]"));
    EXPECT_THAT(error("\"from_deg\": 55, \"to_deg\": 305", "\"from_deg\": 55, \"to_deg\": 40"),
                HasSubstr("project.json: scenery[1].to_deg: must lie above from_deg by at most 360"));
    EXPECT_THAT(error("\"name\": \"rectum\", \"generator\"", "\"name\": \"fat\", \"generator\""),
                HasSubstr("project.json: scenery[0].name: 'fat' is used twice"));
    EXPECT_THAT(error("\"facing\": \"outward\"", "\"facing\": \"sideways\""),
                HasSubstr("project.json: scenery[0].facing: 'sideways' is not a facing (inward, outward)"));
    EXPECT_THAT(error("\"normal\": [-1, 0, 0]", "\"normal\": [0, 0, 0]"),
                HasSubstr("project.json: scenery[2].normal: must not be zero"));
    EXPECT_THAT(error("\"bend\": {\"radius\": 0.032", "\"bend\": {\"radius\": 2"),
                HasSubstr("project.json: bend.radius: must be in [0.005, 1]"));
    // A bend tighter than the sheet is thick: refused at export, naming the field and the node.
    const studio::Project tight = studio::loadProjectText(
        [&] {
            std::string t = text;
            const std::string from = "\"bend\": {\"radius\": 0.032";
            t.replace(t.find(from), from.size(), "\"bend\": {\"radius\": 0.006");
            return t;
        }(),
        src, "project.json");
    const test::Scratch scratch("viscera-bend");
    const std::filesystem::path out = scratch.dir / "r.vcase";
    try {
        studio::exportCase(tight, out);
        FAIL() << "exported a sheet bent past its axis";
    } catch (const InputError& e) {
        EXPECT_THAT(e.what(), HasSubstr("project.json: bend.radius: node "));
        EXPECT_THAT(e.what(), HasSubstr("at or below the bend's axis (radius 0.006"));
    }
    EXPECT_FALSE(std::filesystem::exists(out)) << "nothing written";
}

TEST(AnatomyShapes, ABentSheetOfFatExportsAsAShellWithItsScenery) {
    const test::Scratch scratch("viscera-anatomy");
    const std::filesystem::path out = scratch.dir / "rectum.vcase";
    const studio::Project p = studio::loadProjectText(bentSheetText(), rectumDir(), "bent_sheet_project.json");
    ASSERT_TRUE(p.bend.has_value());
    ASSERT_EQ(p.scenery.size(), 3u);
    // Round trip through the project's text.
    const studio::Project back = studio::loadProjectText(studio::projectJsonText(p), p.dir, "again");
    ASSERT_TRUE(back.bend.has_value());
    EXPECT_DOUBLE_EQ(back.bend->centerY, 0.01);
    ASSERT_EQ(back.scenery.size(), 3u);
    EXPECT_DOUBLE_EQ(back.scenery[1].toDeg, 305);
    studio::exportCase(p, out);
    auto pkg = vcase::CasePackage::open(out);
    const sim::SceneDesc scene = sim::parseScene(pkg->read("scene.json"), "scene.json");
    ASSERT_EQ(scene.scenery.size(), 3u);
    EXPECT_EQ(scene.scenery[0].name, "rectum");
    for (const sim::SceneryDesc& s : scene.scenery)
        EXPECT_GT(sim::parseVtri(pkg->read(s.meshPath), s.meshPath).triangleCount(), 100u) << s.name;
    // The fat is a shell around the rectum: its fixed inner nodes 24 mm from the bend's axis, its
    // top 32 mm.
    const auto fat = sim::parseVtet(pkg->read(scene.bodies[0].meshPath), "fat");
    double minR = 1, maxR = 0;
    for (const Vec3& q : fat->positions()) {
        const double r = std::hypot(q.y() - 0.01, q.z() + 0.032);
        minR = std::min(minR, r);
        maxR = std::max(maxR, r);
    }
    EXPECT_NEAR(minR, 0.024, 1e-9);
    EXPECT_NEAR(maxR, 0.032, 1e-9);
    for (int32_t v : scene.bodies[0].fixedNodes)
        EXPECT_NEAR(std::hypot(fat->positions()[v].y() - 0.01, fat->positions()[v].z() + 0.032), 0.024, 1e-6);
}

// The shipped rectum [issue 57 item 5]: its fat is the mesorectum of `viscera-studio sample rectum`
// through Make simulation-ready and Tetrahedralize, its rectum, pelvic wall and peritoneum are that
// anatomy imported as surroundings, its fascia the fat's top subdivided twice; nothing is bent.
TEST(AnatomyShapes, TheRectumSampleExportsItsImportedAnatomy) {
    const test::Scratch scratch("viscera-anatomy-rectum");
    const std::filesystem::path out = scratch.dir / "rectum.vcase";
    const studio::Project p = studio::loadProject(rectumDir());
    EXPECT_FALSE(p.bend.has_value());
    ASSERT_EQ(p.bodies[0].scene.name, "fat");
    ASSERT_EQ(p.bodies[0].mesh.kind, studio::MeshSource::Kind::Remesh);
    ASSERT_EQ(p.bodies[0].mesh.remesh.parts.size(), 1u);
    EXPECT_EQ(p.bodies[0].mesh.remesh.parts[0].file.filename(), "mesorectum.obj");
    ASSERT_EQ(p.scenery.size(), 3u);
    const char* scenery[] = {"rectum", "pelvic_wall", "peritoneum"};
    for (size_t k = 0; k < 3; ++k) {
        EXPECT_EQ(p.scenery[k].name, scenery[k]);
        EXPECT_EQ(p.scenery[k].file.filename(), std::string(scenery[k]) + ".obj");
    }
    ASSERT_EQ(p.surfaces.size(), 1u);
    EXPECT_EQ(p.surfaces[0].subdivide, 2);
    studio::exportCase(p, out);
    auto pkg = vcase::CasePackage::open(out);
    const sim::SceneDesc scene = sim::parseScene(pkg->read("scene.json"), "scene.json");
    ASSERT_EQ(scene.scenery.size(), 3u);
    for (const sim::SceneryDesc& s : scene.scenery)
        EXPECT_GT(sim::parseVtri(pkg->read(s.meshPath), s.meshPath).triangleCount(), 500u) << s.name;
    // The fat is the shell of the anatomy: inner face 22.5 mm from the rectum's axis, outer 32 mm
    // (lobules ±0.9 mm), to within the remesh's voxel.
    const auto fat = sim::parseVtet(pkg->read(scene.bodies[0].meshPath), "fat");
    auto radius = [](const Vec3& q) { return std::hypot(q.y() - 0.01, q.z() + 0.032); };
    double minR = 1, maxR = 0;
    for (const Vec3& q : fat->positions()) {
        minR = std::min(minR, radius(q));
        maxR = std::max(maxR, radius(q));
    }
    EXPECT_NEAR(minR, 0.0225, 0.001);
    EXPECT_NEAR(maxR, 0.032, 0.0015);
    ASSERT_GT(scene.bodies[0].fixedNodes.size(), 100u);
    // the held boxes follow the inner face in 15° steps: a few nodes past the rectal wall (24.6 mm)
    // at their corners, none in the outer half of the shell
    size_t pastWall = 0;
    for (int32_t v : scene.bodies[0].fixedNodes) {
        EXPECT_LT(radius(fat->positions()[v]), 0.0275) << "node " << v;
        pastWall += radius(fat->positions()[v]) > 0.0246;
    }
    EXPECT_LT(pastWall, scene.bodies[0].fixedNodes.size() / 20);
    EXPECT_GT(fat->tetCount(), 3000u);
    const sim::TriMesh fascia = sim::parseVtri(pkg->read(scene.surfaces[0].meshPath), "fascia");
    EXPECT_GT(fascia.vertexCount(), 2000u) << "subdivided: finer than the fat's boundary";
}
