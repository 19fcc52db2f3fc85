#include "case/case_package.hpp"
#include "project/project.hpp"
#include "render/case_references.hpp"
#include "render/sample_map.hpp"
#include "sim/collision/distance.hpp"
#include "sim/mesh/tet_io.hpp"
#include "sim/scene/scene.hpp"
#include "sim/scene/scene_json.hpp"
#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <set>

#include <sys/stat.h>
#include <unistd.h>

using namespace viscera;
using ::testing::HasSubstr;

namespace {

class ProjectTest : public ::testing::Test {
protected:
    void SetUp() override {
        m_dir =
            std::filesystem::temp_directory_path() / ("viscera_project_" + std::to_string(::getpid()) + "_" +
                                                      ::testing::UnitTest::GetInstance()->current_test_info()->name());
        std::filesystem::create_directories(m_dir);
    }
    void TearDown() override { std::filesystem::remove_all(m_dir); }
    void write(const std::string& text) { writeFileAtomic(m_dir / "project.json", text); }
    std::string loadError() {
        try {
            studio::loadProject(m_dir);
        } catch (const InputError& e) {
            return e.what();
        }
        return "accepted";
    }
    std::filesystem::path m_dir;
};

const char* kGood = R"({
  "schemaVersion": 1, "caseId": "mini", "caseVersion": "1.0.0", "title": "Mini",
  "solver": {"type": "xpbd", "substeps": 100},
  "gravity": [0, 0, -9.81],
  "bodies": [{"name": "slab",
              "mesh": {"generator": "box", "size": [0.04, 0.01, 0.01], "cells": [4, 1, 1]},
              "material": {"model": "stable_neo_hookean", "youngs_modulus": 20000, "poisson_ratio": 0.4, "density": 1000},
              "fixed": {"min": [-1, -1, -1], "max": [0.0001, 1, 1]}}]
})";

std::string replaced(std::string s, const std::string& from, const std::string& to) {
    s.replace(s.find(from), from.size(), to);
    return s;
}

} // namespace

TEST_F(ProjectTest, ExportWritesOnlyWhatTheSceneUses) {
    write(kGood);
    studio::Project p = studio::loadProject(m_dir);
    auto out = m_dir / "mini.vcase";
    studio::ExportResult r = studio::exportCase(p, out);
    EXPECT_EQ(r.features, (std::vector<std::string>{"gravity", "xpbd"}));
    ASSERT_EQ(r.bodies.size(), 1u);
    EXPECT_EQ(r.bodies[0].tets, 24u);
    EXPECT_EQ(r.bodies[0].fixedNodes, 4u);
    auto pkg = vcase::CasePackage::open(out);
    ASSERT_EQ(pkg->manifest().files.size(), 2u);
    EXPECT_TRUE(pkg->contains("scene.json"));
    EXPECT_TRUE(pkg->contains("meshes/slab.vtet"));
    EXPECT_EQ(pkg->manifest().title.value_or(""), "Mini");

    // No gravity: the gravity feature is left out of the manifest.
    write(replaced(kGood, "\"gravity\": [0, 0, -9.81],", ""));
    studio::ExportResult still = studio::exportCase(studio::loadProject(m_dir), out);
    EXPECT_EQ(still.features, std::vector<std::string>{"xpbd"});
}

// Export writes by the one table of file references that load checks
// (render::caseFileReferences): the packages of the liver (meshes, a fascia, texture maps, a light
// sample map), the anastomosis (a needle trajectory) and the rectum (scenery surfaces, tracks) hold
// exactly scene.json and the files their
// scenes name, each named once with its field.
TEST_F(ProjectTest, PackagesHoldExactlyTheFilesTheirScenesName) {
    for (const char* sample : {"liver", "anastomosis", "rectum"}) {
        SCOPED_TRACE(sample);
        const auto out = m_dir / (std::string(sample) + ".vcase");
        studio::exportCase(studio::loadProject(std::filesystem::path(VISCERA_SOURCE_DIR) / "projects" / sample), out);
        auto pkg = vcase::CasePackage::open(out);
        const sim::SceneDesc scene = sim::parseScene(pkg->read("scene.json"), "scene.json");
        std::set<std::string> named = {"scene.json"}, packaged;
        for (const render::CaseFileRef& ref :
             render::caseFileReferences(scene, render::caseMaterialMaps(scene.render, "scene.json"))) {
            EXPECT_FALSE(ref.field.empty()) << ref.path;
            EXPECT_TRUE(named.insert(ref.path).second) << ref.path << " listed twice";
        }
        for (const vcase::FileEntry& f : pkg->manifest().files)
            packaged.insert(f.path);
        EXPECT_EQ(packaged, named);
        EXPECT_GE(named.size(), std::string(sample) == "liver" ? 5u : 3u);
    }
    // The table on a scene that names every kind of file, one path twice.
    sim::SceneDesc scene;
    scene.bodies.resize(2);
    scene.bodies[0].meshPath = "meshes/a.vtet";
    scene.bodies[0].nodeWeightsPath = "meshes/a.vweights";
    scene.bodies[1].meshPath = "meshes/b.vtet";
    scene.bodies[1].sampleMapPath = "meshes/b.vsamples";
    scene.surfaces.resize(1);
    scene.surfaces[0].meshPath = "meshes/a.vtet"; // the same path again: listed once
    scene.render = R"({"materials": {"b": {"diffuse": "textures/b.png"}}})";
    std::vector<std::pair<std::string, std::string>> got;
    for (const render::CaseFileRef& ref :
         render::caseFileReferences(scene, render::caseMaterialMaps(scene.render, "scene.json")))
        got.emplace_back(ref.field, ref.path);
    EXPECT_EQ(got,
              (std::vector<std::pair<std::string, std::string>>{{"bodies[0].mesh", "meshes/a.vtet"},
                                                                {"bodies[0].node_weights_file", "meshes/a.vweights"},
                                                                {"bodies[1].mesh", "meshes/b.vtet"},
                                                                {"bodies[1].sample_map_file", "meshes/b.vsamples"},
                                                                {"render.materials.b", "textures/b.png"}}));
}

TEST_F(ProjectTest, LoadErrorsNameFileFieldAndRule) {
    write("{");
    EXPECT_THAT(loadError(), HasSubstr("project.json: invalid JSON ("));
    write(replaced(kGood, "\"cells\": [4, 1, 1]", "\"cells\": [4, 0, 1]"));
    EXPECT_THAT(loadError(), HasSubstr("project.json: bodies[0].mesh.cells[1]: must be an integer in [1, 512]"));
    write(replaced(kGood, "\"poisson_ratio\": 0.4", "\"poisson_ratio\": 0.5"));
    EXPECT_THAT(loadError(), HasSubstr("bodies[0].material.poisson_ratio: must be in [0, 0.5)"));
    write(replaced(kGood, "\"title\": \"Mini\",", "\"titel\": \"Mini\","));
    EXPECT_THAT(loadError(), HasSubstr("project.json: titel: unknown field"));
    write(replaced(kGood, "\"generator\": \"box\"", "\"generator\": \"torus\""));
    EXPECT_THAT(loadError(), HasSubstr("bodies[0].mesh.generator: 'torus' is not a known generator"));
    write(replaced(kGood, "\"mesh\": {\"generator\": \"box\", \"size\": [0.04, 0.01, 0.01], \"cells\": [4, 1, 1]}",
                   "\"mesh\": {\"file\": \"../../etc/organ.obj\"}"));
    EXPECT_THAT(
        loadError(),
        HasSubstr("bodies[0].mesh.file: '../../etc/organ.obj': entry name escapes the package ('..' component)"));
    std::filesystem::remove(m_dir / "project.json");
    EXPECT_THAT(loadError(), HasSubstr("project.json: cannot open for reading"));
}

TEST_F(ProjectTest, ExportRefusesEmptyFixedRegionAndKeepsTheOldCase) {
    write(kGood);
    auto out = m_dir / "mini.vcase";
    studio::exportCase(studio::loadProject(m_dir), out);
    const auto before = std::filesystem::file_size(out);
    write(replaced(kGood, "\"min\": [-1, -1, -1], \"max\": [0.0001, 1, 1]", "\"min\": [5, 5, 5], \"max\": [6, 6, 6]"));
    try {
        studio::exportCase(studio::loadProject(m_dir), out);
        FAIL();
    } catch (const InputError& e) {
        EXPECT_THAT(e.what(), HasSubstr("bodies[0] ('slab').fixed: the box contains no mesh node"));
    }
    EXPECT_EQ(std::filesystem::file_size(out), before) << "a failed export leaves the previous case intact";
}

// Several held regions [issue 57 item 4]: a body attached at more than one place (a duct to the
// gallbladder and to the common bile duct) lists its boxes; a node in any one is fixed; each box
// must hold a node; the list round-trips.
TEST_F(ProjectTest, ABodyHeldInSeveralBoxesFixesTheNodesOfEach) {
    const std::string one = "\"fixed\": {\"min\": [-1, -1, -1], \"max\": [0.0001, 1, 1]}";
    const std::string two = "\"fixed\": [{\"min\": [-1, -1, -1], \"max\": [0.0001, 1, 1]}, "
                            "{\"min\": [0.0399, -1, -1], \"max\": [1, 1, 1]}]";
    write(replaced(kGood, one, two));
    const studio::Project p = studio::loadProject(m_dir);
    ASSERT_EQ(p.bodies[0].fixedBoxes.size(), 2u);
    studio::ExportResult r = studio::exportCase(p, m_dir / "held.vcase");
    EXPECT_EQ(r.bodies[0].fixedNodes, 8u) << "both end faces of the 4 x 1 x 1 box";
    studio::saveProject(p, m_dir);
    EXPECT_EQ(studio::loadProject(m_dir).bodies[0].fixedBoxes, p.bodies[0].fixedBoxes) << "the list round-trips";
    write(replaced(kGood, one, "\"fixed\": []"));
    EXPECT_THAT(loadError(), HasSubstr("bodies[0].fixed"));
    write(replaced(kGood, one,
                   "\"fixed\": [{\"min\": [-1, -1, -1], \"max\": [0.0001, 1, 1]}, "
                   "{\"min\": [5, 5, 5], \"max\": [6, 6, 6]}]"));
    try {
        studio::exportCase(studio::loadProject(m_dir), m_dir / "held2.vcase");
        FAIL();
    } catch (const InputError& e) {
        EXPECT_THAT(e.what(), HasSubstr("bodies[0] ('slab').fixed[1]: the box contains no mesh node"));
    }
}

TEST_F(ProjectTest, ImportedSurfaceIsTetrahedralized) {
    // A closed box surface written as OBJ, imported and meshed with CGAL through the project.
    writeFileAtomic(m_dir / "cube.obj",
                    "v 0 0 0\nv 10 0 0\nv 0 10 0\nv 10 10 0\nv 0 0 10\nv 10 0 10\nv 0 10 10\nv 10 10 10\n"
                    "f 1 3 4\nf 1 4 2\nf 5 6 8\nf 5 8 7\nf 1 2 6\nf 1 6 5\nf 3 7 8\nf 3 8 4\nf 1 5 7\nf 1 7 3\n"
                    "f 2 4 8\nf 2 8 6\n");
    write(replaced(kGood, "\"mesh\": {\"generator\": \"box\", \"size\": [0.04, 0.01, 0.01], \"cells\": [4, 1, 1]}",
                   "\"mesh\": {\"file\": \"cube.obj\", \"scale\": 0.001, \"meshing\": {\"cell_size\": 0.004, "
                   "\"facet_size\": 0.004, \"seed\": 1}}"));
    studio::ExportResult r = studio::exportCase(studio::loadProject(m_dir), m_dir / "cube.vcase");
    ASSERT_EQ(r.bodies.size(), 1u);
    EXPECT_GT(r.bodies[0].tets, 20u);
    EXPECT_NEAR(r.bodies[0].quality.totalVolume, 1e-6, 0.02e-6);
    EXPECT_GT(r.bodies[0].fixedNodes, 0u);
}

namespace {

/// Painted weight mass of a body: ∫ (w − base) dV with w linear on each tet (its nodes' mean), m³.
double paintedMass(const sim::TetMesh& mesh, const std::vector<double>& w, double base) {
    double m = 0;
    for (size_t t = 0; t < mesh.tetCount(); ++t) {
        double mean = 0;
        for (int32_t v : mesh.tets()[t])
            mean += w[v];
        m += std::abs(mesh.signedVolume(static_cast<int32_t>(t))) * (mean / 4 - base);
    }
    return m;
}

} // namespace

TEST_F(ProjectTest, RemeshingABodyKeepsItsPaintedWeightMass) {
    // Strokes are stored by position (mesh frame): a body meshed again with other parameters is
    // painted by the same strokes. The rectum's fat (remeshed anatomy) and vessel (hollow tube), each meshed
    // two ways: at least 99 % of the painted mass is kept (and it does not grow by more than the
    // discretization can explain, 5 %: the poly6 field is sampled at other nodes).
    studio::Project p = studio::loadProject(std::filesystem::path(VISCERA_SOURCE_DIR) / "projects/rectum");
    p.dir = m_dir;
    ASSERT_GE(p.bodies.size(), 2u);
    studio::BodyProject& fat = p.bodies[0];
    studio::BodyProject& vessel = p.bodies[1];
    ASSERT_TRUE(fat.paint.has_value());
    fat.paint->strokes.push_back({sim::Vec3(0.02, 0.01, -0.005), 0.025, 3.0}); // in the fat's top
    sim::BrushStroke mix{sim::Vec3(-0.03, 0.02, -0.004), 0.02, 0.7};
    mix.mode = sim::BrushMode::Mix;
    mix.target = 0.3;
    fat.paint->strokes.push_back(mix);
    const sim::Vec3 a = vessel.mesh.hollow.start, b = vessel.mesh.hollow.end;
    vessel.paint = studio::StiffnessPaintProject{};
    vessel.paint->strokes.push_back({0.5 * (a + b), 0.015, 4.0});
    vessel.paint->strokes.push_back({0.8 * a + 0.2 * b, 0.01, -0.5});

    studio::Project q = p;
    q.bodies[0].mesh.meshing.cellSize = 0.004; // the imported mesorectum, tetrahedralized finer
    q.bodies[0].mesh.meshing.facetSize = 0.004;
    q.bodies[1].mesh.hollow.rings = 31;
    q.bodies[1].mesh.hollow.slices = 16;
    q.bodies[1].mesh.hollow.layers = 2;
    const studio::BuiltScene A = studio::buildScene(p), B = studio::buildScene(q);
    for (size_t i = 0; i < 2; ++i) {
        SCOPED_TRACE(p.bodies[i].scene.name);
        ASSERT_NE(A.meshes[i]->vertexCount(), B.meshes[i]->vertexCount()) << "meshed again, differently";
        const double base = p.bodies[i].paint->params.baseWeight;
        const double ma = paintedMass(*A.meshes[i], A.scene.bodies[i].nodeWeights, base);
        const double mb = paintedMass(*B.meshes[i], B.scene.bodies[i].nodeWeights, base);
        std::printf("%s: %zu -> %zu nodes, painted mass %.6g -> %.6g m^3 (%.2f %%)\n", p.bodies[i].scene.name.c_str(),
                    A.meshes[i]->vertexCount(), B.meshes[i]->vertexCount(), ma, mb, 100.0 * mb / ma);
        ASSERT_GT(ma, 0.0);
        EXPECT_GE(mb / ma, 0.99);
        EXPECT_LE(mb / ma, 1.05);
    }
}

TEST_F(ProjectTest, RemeshingKeepsAFasciasPaintedWeightMass) {
    // Polygon paint on the liver's fascia is stored by position: the organ meshed again (another
    // cell size, so another cut surface) gets the same strokes; >= 99 % of the painted area mass
    // ∫ (w − base) dA is kept.
    studio::Project p = studio::loadProject(std::filesystem::path(VISCERA_SOURCE_DIR) / "projects/liver");
    p.dir = m_dir;
    ASSERT_FALSE(p.surfaces.empty());
    studio::StiffnessPaintProject paint;
    paint.params.maxWeight = 50;
    paint.strokes.push_back({sim::Vec3(0.0, -0.02, 0.04), 0.05, 8.0});
    paint.strokes.push_back({sim::Vec3(0.05, 0.01, 0.02), 0.03, 0.6});
    sim::BrushStroke smooth{sim::Vec3(0.02, 0.0, 0.04), 0.04, 0.5};
    smooth.mode = sim::BrushMode::Smooth;
    paint.strokes.push_back(smooth);
    p.surfaces[0].paint = paint;
    studio::Project q = p;
    q.bodies[0].mesh.meshing.cellSize *= 0.8;
    q.bodies[0].mesh.meshing.facetSize *= 0.8;
    const studio::BuiltScene A = studio::buildScene(p), B = studio::buildScene(q);
    auto mass = [](const sim::TriMesh& m, const std::vector<double>& w) {
        double sum = 0;
        for (size_t t = 0; t < m.triangleCount(); ++t) {
            const sim::Tri& f = m.triangles()[t];
            const sim::Vec3 &a = m.positions()[f[0]], &b = m.positions()[f[1]], &c = m.positions()[f[2]];
            sum += 0.5 * (b - a).cross(c - a).norm() * ((w[f[0]] + w[f[1]] + w[f[2]]) / 3 - 1.0);
        }
        return sum;
    };
    ASSERT_EQ(A.scene.surfaces[0].nodeWeights.size(), A.surfaces[0].vertexCount());
    ASSERT_EQ(B.scene.surfaces[0].nodeWeights.size(), B.surfaces[0].vertexCount());
    ASSERT_NE(A.surfaces[0].vertexCount(), B.surfaces[0].vertexCount()) << "cut again, differently";
    EXPECT_EQ(A.scene.surfaces[0].nodeWeightsPath, "meshes/fascia.vweights");
    const double ma = mass(A.surfaces[0], A.scene.surfaces[0].nodeWeights);
    const double mb = mass(B.surfaces[0], B.scene.surfaces[0].nodeWeights);
    std::printf("fascia: %zu -> %zu vertices, painted area mass %.6g -> %.6g m^2 (%.2f %%)\n",
                A.surfaces[0].vertexCount(), B.surfaces[0].vertexCount(), ma, mb, 100.0 * mb / ma);
    ASSERT_GT(ma, 0.0);
    EXPECT_GE(mb / ma, 0.99);
    EXPECT_LE(mb / ma, 1.05);
    // the project text round-trips the surface's paint (no skeleton block on a fascia)
    const std::string text = studio::projectJsonText(p);
    EXPECT_EQ(studio::projectJsonText(studio::loadProjectText(text, m_dir, "again")), text);
    EXPECT_EQ(nlohmann::json::parse(text)["surfaces"][0]["stiffness_paint"].count("skeleton"), 0u);
    nlohmann::json bad = nlohmann::json::parse(text);
    bad["surfaces"][0]["stiffness_paint"]["skeleton"] = nlohmann::json::object();
    try {
        studio::loadProjectText(bad.dump(), m_dir, "p.json");
        ADD_FAILURE() << "a skeleton on a fascia was accepted";
    } catch (const InputError& e) {
        EXPECT_THAT(e.what(), HasSubstr("p.json: surfaces[0].stiffness_paint"));
        EXPECT_THAT(e.what(), HasSubstr("skeleton"));
    }
}

// "subdivide" on a layer [issue 57 item 5]: each round splits every triangle of the body's boundary
// in four at its edge midpoints, so the fascia is finer than the tets under it while it still lies
// on their boundary (the solver attaches every vertex); the region is cut after subdividing, so its
// border steps by the finer triangles; the field round-trips and 0..3 is the rule.
TEST_F(ProjectTest, ASubdividedFasciaIsFinerAndStillLiesOnItsBody) {
    studio::Project p = studio::loadProject(std::filesystem::path(VISCERA_SOURCE_DIR) / "projects/liver");
    p.dir = m_dir;
    ASSERT_FALSE(p.surfaces.empty());
    EXPECT_EQ(p.surfaces[0].subdivide, 0);
    ASSERT_TRUE(p.surfaces[0].region.has_value());
    {
        // with its region (z >= 0): every finer triangle's centroid in it, about the same area
        studio::Project r = p;
        r.surfaces[0].subdivide = 2;
        const studio::BuiltScene C = studio::buildScene(p), D = studio::buildScene(r);
        const sim::TriMesh &c = C.surfaces[0], &d = D.surfaces[0];
        double area[2] = {0, 0};
        for (int k = 0; k < 2; ++k)
            for (const sim::Tri& t : (k ? d : c).triangles()) {
                const std::vector<sim::Vec3>& x = (k ? d : c).positions();
                area[k] += 0.5 * (x[t[1]] - x[t[0]]).cross(x[t[2]] - x[t[0]]).norm();
                if (k) EXPECT_GE((x[t[0]] + x[t[1]] + x[t[2]]).z() / 3, 0.0);
            }
        EXPECT_NEAR(area[1], area[0], 0.1 * area[0]);
    }
    p.surfaces[0].region.reset(); // the whole boundary: exactly four triangles for one, twice
    studio::Project q = p;
    q.surfaces[0].subdivide = 2;
    const studio::BuiltScene A = studio::buildScene(p), B = studio::buildScene(q);
    const sim::TriMesh &a = A.surfaces[0], &b = B.surfaces[0];
    EXPECT_EQ(b.triangleCount(), 16 * a.triangleCount());
    auto meanEdge = [](const sim::TriMesh& m) {
        double sum = 0;
        for (const sim::Tri& t : m.triangles())
            for (int k = 0; k < 3; ++k)
                sum += (m.positions()[t[k]] - m.positions()[t[(k + 1) % 3]]).norm();
        return sum / (3.0 * double(m.triangleCount()));
    };
    EXPECT_NEAR(meanEdge(b) / meanEdge(a), 0.25, 1e-9);
    double area[2] = {0, 0};
    for (int k = 0; k < 2; ++k) {
        const sim::TriMesh& m = k ? b : a;
        for (const sim::Tri& t : m.triangles())
            area[k] +=
                0.5 *
                (m.positions()[t[1]] - m.positions()[t[0]]).cross(m.positions()[t[2]] - m.positions()[t[0]]).norm();
    }
    EXPECT_NEAR(area[1], area[0], 1e-12) << "the same surface, only finer";
    // every vertex of the finer layer lies on the body's boundary (on one of its flat triangles)
    const sim::TriMesh& boundary = B.meshes[0]->boundary();
    size_t off = 0;
    for (const sim::Vec3& x : b.positions()) {
        double best = 1e9;
        for (const sim::Tri& t : boundary.triangles())
            best = std::min(best, (sim::closestPointOnTriangle(x, boundary.positions()[t[0]],
                                                               boundary.positions()[t[1]], boundary.positions()[t[2]])
                                       .point -
                                   x)
                                      .norm());
        off += best > 1e-9;
    }
    EXPECT_EQ(off, 0u);
    const std::string text = studio::projectJsonText(q);
    EXPECT_EQ(nlohmann::json::parse(text)["surfaces"][0]["subdivide"], 2);
    EXPECT_EQ(studio::loadProjectText(text, m_dir, "again").surfaces[0].subdivide, 2);
    EXPECT_EQ(nlohmann::json::parse(studio::projectJsonText(p))["surfaces"][0].count("subdivide"), 0u);
    nlohmann::json bad = nlohmann::json::parse(text);
    bad["surfaces"][0]["subdivide"] = 4;
    try {
        studio::loadProjectText(bad.dump(), m_dir, "bad");
        ADD_FAILURE() << "subdivide 4 accepted";
    } catch (const std::exception& e) {
        EXPECT_THAT(e.what(), HasSubstr("surfaces[0].subdivide: must be an integer in [0, 3]"));
    }
}

TEST_F(ProjectTest, SampleMapIsPackagedOnlyWhenTheSceneUsesPaintedSampling) {
    const std::string painted =
        replaced(replaced(kGood, "\"gravity\"", "\"render\": {\"sampling\": \"painted\"}, \"gravity\""), "\"fixed\":",
                 "\"light_samples\": [{\"tool\": \"fill\", \"samples\": 4, \"seed\": [0.02, 0.005, 0.0101]},"
                 " {\"tool\": \"brush\", \"samples\": 8, \"radius\": 0.006, \"points\": [[0.0, 0.0, 0.0]]}],"
                 " \"fixed\":");
    write(painted);
    const studio::Project p = studio::loadProject(m_dir);
    ASSERT_EQ(p.bodies[0].lightSamples.size(), 2u);
    EXPECT_TRUE(studio::usesPaintedSampling(p.scene));
    // the text round-trips
    EXPECT_EQ(studio::projectJsonText(studio::loadProjectText(studio::projectJsonText(p), m_dir, "again")),
              studio::projectJsonText(p));
    const auto out = m_dir / "mini.vcase";
    studio::exportCase(p, out);
    auto pkg = vcase::CasePackage::open(out);
    ASSERT_TRUE(pkg->contains("maps/slab.vsamples"));
    const sim::SceneDesc scene = sim::parseScene(pkg->read("scene.json"), "scene.json");
    EXPECT_EQ(scene.bodies[0].sampleMapPath, "maps/slab.vsamples");
    const auto mesh = sim::parseVtet(pkg->read("meshes/slab.vtet"), "slab.vtet");
    const std::vector<uint8_t> nodes =
        render::parseSampleMap(pkg->read("maps/slab.vsamples"), "slab.vsamples", mesh->vertexCount());
    // the classes are the operations replayed on the body's surface at rest
    render::RenderMesh surface = render::bodySurfaceMesh(*mesh, "slab");
    render::applySamplePaint(surface, p.bodies[0].lightSamples);
    EXPECT_EQ(nodes, render::nodeSampleClasses(surface, mesh->vertexCount()));
    // the fill's top side (z = 0.01) is 4×, the other sides are not painted by it
    size_t four = 0;
    for (size_t v = 0; v < mesh->vertexCount(); ++v) {
        const sim::Vec3& x = mesh->positions()[v];
        four += nodes[v] == 4;
        if (x.z() < 0.01 - 1e-9 && x.norm() > 0.006 + 0.01) EXPECT_EQ(nodes[v], 0) << "node " << v;
    }
    EXPECT_GT(four, 2u);
    // another sampling mode: the map stays in the project but is not packaged
    write(replaced(painted, "\"painted\"", "\"distance\""));
    studio::exportCase(studio::loadProject(m_dir), out);
    auto plain = vcase::CasePackage::open(out);
    EXPECT_FALSE(plain->contains("maps/slab.vsamples"));
    EXPECT_TRUE(sim::parseScene(plain->read("scene.json"), "scene.json").bodies[0].sampleMapPath.empty());
    // bad operations are refused naming the field and the rule
    write(replaced(painted, "\"samples\": 4", "\"samples\": 3"));
    EXPECT_THAT(loadError(), HasSubstr("bodies[0].light_samples[0].samples: must be 0 (erase), 1, 4 or 8"));
    write(replaced(painted, "\"radius\": 0.006", "\"radius\": -1"));
    EXPECT_THAT(loadError(), HasSubstr("bodies[0].light_samples[1].radius: "));
    write(replaced(painted, "\"points\": [[0.0, 0.0, 0.0]]", "\"points\": []"));
    EXPECT_THAT(loadError(), HasSubstr("bodies[0].light_samples[1].points"));
    write(replaced(painted, "\"tool\": \"fill\"", "\"tool\": \"spray\""));
    EXPECT_THAT(loadError(), HasSubstr("bodies[0].light_samples[0].tool"));
    write(replaced(painted, "\"seed\"", "\"radius\": 0.01, \"seed\""));
    EXPECT_THAT(loadError(), HasSubstr("bodies[0].light_samples[0].radius: unknown field"));
}

TEST_F(ProjectTest, RemeshingABodyKeepsItsSampleClassArea) {
    // Light-sample operations are stored by position: the liver's organ meshed again with other
    // CGAL parameters is painted by the same operations. Each painted class keeps at least 99 %
    // of its area and grows by at most 1 % (the replay keeps the painted area to within a vertex
    // cell on any mesh).
    studio::Project p = studio::loadProject(std::filesystem::path(VISCERA_SOURCE_DIR) / "projects/liver");
    p.dir = m_dir;
    ASSERT_FALSE(p.bodies[0].lightSamples.empty()) << "the liver sample has painted light samples";
    ASSERT_TRUE(studio::usesPaintedSampling(p.scene));
    studio::Project q = p;
    q.bodies[0].mesh.meshing.facetSize *= 0.75;
    q.bodies[0].mesh.meshing.cellSize *= 0.75;
    q.bodies[0].mesh.meshing.seed += 1;
    const studio::BuiltScene A = studio::buildScene(p), B = studio::buildScene(q);
    auto classAreas = [](const studio::BuiltScene& built) {
        std::string map;
        for (const auto& [path, bytes] : built.files)
            if (path == "maps/organ.vsamples") map = bytes;
        const sim::TetMesh& mesh = *built.meshes[0];
        const std::vector<uint8_t> nodes = render::parseSampleMap(map, "organ.vsamples", mesh.vertexCount());
        render::RenderMesh surface = render::bodySurfaceMesh(mesh, "organ");
        for (size_t v = 0; v < surface.vertexCount(); ++v)
            surface.sampleMap[v] = nodes[surface.sourceVertex[v]];
        return render::sampleClassAreas(surface);
    };
    ASSERT_NE(A.meshes[0]->vertexCount(), B.meshes[0]->vertexCount()) << "meshed again, differently";
    const auto a = classAreas(A), b = classAreas(B);
    const char* names[] = {"unpainted", "1x", "4x", "8x"};
    int painted = 0;
    for (int c = 1; c < 4; ++c) {
        if (a[c] == 0) continue;
        ++painted;
        std::printf("organ %s: %zu -> %zu nodes, area %.4g -> %.4g cm^2 (%.2f %%)\n", names[c],
                    A.meshes[0]->vertexCount(), B.meshes[0]->vertexCount(), a[c] * 1e4, b[c] * 1e4,
                    100.0 * b[c] / a[c]);
        EXPECT_GE(b[c] / a[c], 0.99) << names[c];
        EXPECT_LE(b[c] / a[c], 1.01) << names[c];
    }
    EXPECT_GE(painted, 2);
}

namespace {

/// A small texture spec writing `maps` (the "maps" object's text).
std::string textureSpec(const std::string& maps) {
    return R"({"name": "t", "size": 32, "seed": 4, "levels": 4,
  "patterns": [{"level": 2, "tile": {"shape": "bell"}, "opacity": [0.5, 1]}],
  "palette": {"colors": ["#802020", "#e0a090"]},
  "maps": )" +
           maps + "}";
}

} // namespace

TEST_F(ProjectTest, TexturedBodiesPackageExactlyTheMapsTheRendererSamples) {
    // [A §6.2.2] a body's texture spec makes its maps at export: diffuse, roughness and normal are
    // packaged and named in render.materials; the mask and height the spec also writes are not
    std::filesystem::create_directories(m_dir / "textures");
    writeFileAtomic(m_dir / "textures/slab.json",
                    textureSpec(R"({"mask": {}, "diffuse": {"colors": [0, 1]}, "roughness": {"values": [0.5, 0.2]},
                        "height": {}, "normal": {"depth": 0.01}})"));
    write(replaced(
        kGood, "\"fixed\":", "\"texture\": {\"spec\": \"textures/slab.json\", \"tiles_per_metre\": 50}, \"fixed\":"));
    const studio::Project p = studio::loadProject(m_dir);
    ASSERT_TRUE(p.bodies[0].texture.has_value());
    EXPECT_EQ(studio::projectJsonText(studio::loadProjectText(studio::projectJsonText(p), m_dir, "again")),
              studio::projectJsonText(p));
    const auto out = m_dir / "t.vcase";
    studio::exportCase(p, out);
    std::vector<std::string> maps;
    for (const vcase::FileEntry& f : vcase::verify(out).files)
        if (f.path.rfind("textures/", 0) == 0) maps.push_back(f.path);
    EXPECT_EQ(maps, (std::vector<std::string>{"textures/slab_diffuse.png", "textures/slab_normal.png",
                                              "textures/slab_roughness.png"}));
    const auto pkg = vcase::CasePackage::open(out);
    const auto entries =
        render::caseMaterialMaps(nlohmann::json::parse(pkg->read("scene.json"))["render"].dump(), "scene.json");
    ASSERT_EQ(entries.size(), 1u);
    EXPECT_EQ(entries[0].target, "slab");
    EXPECT_EQ(entries[0].diffuse, "textures/slab_diffuse.png");
    EXPECT_TRUE(entries[0].metallic.empty()) << "the spec writes no metallic map";
    EXPECT_FLOAT_EQ(entries[0].tilesPerMetre, 50.0f);
    // the packaged maps decode and have one size
    const auto decoded = render::loadMaterialMaps(
        entries[0], [&](const std::string& f) { return pkg->read(f); }, "t.vcase");
    EXPECT_EQ(decoded->diffuse.width, 32);
    EXPECT_EQ(decoded->normal.height, 32);
    // without the texture block: no texture in the case
    write(kGood);
    studio::exportCase(studio::loadProject(m_dir), out);
    for (const vcase::FileEntry& f : vcase::verify(out).files)
        EXPECT_NE(f.path.rfind("textures/", 0), 0u) << f.path;
}

TEST_F(ProjectTest, BadTextureBlocksAreRefusedNamingTheFieldAndTheRule) {
    std::filesystem::create_directories(m_dir / "textures");
    const std::string where = (m_dir / "project.json").string() + ": ";
    auto with = [&](const std::string& texture) {
        write(replaced(kGood, "\"fixed\":", "\"texture\": " + texture + ", \"fixed\":"));
        return loadError();
    };
    EXPECT_EQ(with(R"({"spec": "../outside.json"})").rfind(where + "bodies[0].texture.spec: ", 0), 0u);
    EXPECT_EQ(with(R"({"spec": "t.json", "tiles_per_metre": -1})"),
              where + "bodies[0].texture.tiles_per_metre: must be in (0, 10000]");
    EXPECT_EQ(with(R"({"spec": "t.json", "normal_strength": 9})"),
              where + "bodies[0].texture.normal_strength: must be in [0, 4]");
    EXPECT_EQ(with(R"({"spec": "t.json", "colour": 1})"), where + "bodies[0].texture.colour: unknown field");
    // render.materials is the export's to write
    write(replaced(kGood, "\"gravity\"", "\"render\": {\"materials\": {}}, \"gravity\""));
    EXPECT_EQ(loadError().rfind(where + "render.materials: is written by export", 0), 0u) << loadError();
    // at export: a missing spec, and a spec that writes nothing the renderer samples
    auto exportError = [&](const std::string& spec) {
        write(replaced(kGood, "\"fixed\":", "\"texture\": {\"spec\": \"" + spec + "\"}, \"fixed\":"));
        try {
            studio::exportCase(studio::loadProject(m_dir), m_dir / "x.vcase");
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return std::string("exported");
    };
    EXPECT_THAT(exportError("textures/none.json"), HasSubstr("none.json"));
    writeFileAtomic(m_dir / "textures/h.json", textureSpec(R"({"mask": {}, "height": {}})"));
    EXPECT_THAT(exportError("textures/h.json"),
                HasSubstr("h.json: maps: writes none of diffuse, roughness, metallic, normal"));
    EXPECT_FALSE(std::filesystem::exists(m_dir / "x.vcase")) << "nothing written by a failed export";
}

TEST_F(ProjectTest, AGeneratorKeptInTheProjectIsReadByTheSpecReaderAndBakesLikeItsFile) {
    // the same spec as a file and as "generator" gives the same packaged bytes
    std::filesystem::create_directories(m_dir / "textures" / "tiles");
    const std::string maps = R"({"diffuse": {"colors": [0, 1]}, "roughness": {"values": [0.5, 0.2]}})";
    writeFileAtomic(m_dir / "textures/slab.json", textureSpec(maps));
    write(replaced(kGood, "\"fixed\":", "\"texture\": {\"spec\": \"textures/slab.json\"}, \"fixed\":"));
    const studio::Project fromFile = studio::loadProject(m_dir);
    const studio::ProjectTextures a = studio::bakeProjectTextures(fromFile);
    write(replaced(kGood, "\"fixed\":", "\"texture\": {\"generator\": " + textureSpec(maps) + "}, \"fixed\":"));
    const studio::Project inlined = studio::loadProject(m_dir);
    ASSERT_TRUE(inlined.bodies[0].texture);
    EXPECT_TRUE(inlined.bodies[0].texture->spec.empty());
    EXPECT_EQ(studio::projectJsonText(studio::loadProjectText(studio::projectJsonText(inlined), m_dir, "again")),
              studio::projectJsonText(inlined));
    const studio::ProjectTextures b = studio::bakeProjectTextures(inlined);
    ASSERT_EQ(a.files.size(), 2u);
    EXPECT_EQ(a.files, b.files);

    // embedding a file spec: its file references move from the spec's folder onto the project's
    bake::GrayImage tile;
    tile.width = tile.height = 8;
    tile.pixels.assign(64, 0.5f);
    writeFileAtomic(m_dir / "textures/tiles/dot.png", bake::encodePng(tile, 8));
    const std::string withImage = R"({"size": 32, "seed": 4, "levels": 4,
      "patterns": [{"level": 2, "tile": {"shape": "image", "file": "tiles/dot.png"}}],
      "palette": {"colors": ["#802020", "#e0a090"]}, "maps": )" +
                                  maps + "}";
    writeFileAtomic(m_dir / "textures/img.json", withImage);
    studio::TextureProject file;
    file.spec = "textures/img.json";
    file.tilesPerMetre = 33;
    const studio::TextureProject embedded = studio::embedTextureSpec(file, m_dir);
    EXPECT_TRUE(embedded.spec.empty());
    EXPECT_EQ(embedded.tilesPerMetre, 33.0f);
    const nlohmann::json g = nlohmann::json::parse(embedded.generator);
    EXPECT_EQ(g["patterns"][0]["tile"]["file"], "textures/tiles/dot.png");
    EXPECT_EQ(g["name"], "img"); // the map files keep the file's name
    const bake::TextureSpec spec = studio::loadTextureBlock(embedded, m_dir, "inline");
    EXPECT_EQ(bake::specInputFiles(spec), std::vector<std::string>{"textures/tiles/dot.png"});
    EXPECT_EQ(studio::embedTextureSpec(embedded, m_dir), embedded); // already embedded

    // refusals name the project, the field inside the generator and the rule
    const std::string where = (m_dir / "project.json").string() + ": ";
    auto with = [&](const std::string& texture) {
        write(replaced(kGood, "\"fixed\":", "\"texture\": " + texture + ", \"fixed\":"));
        return loadError();
    };
    EXPECT_EQ(with(R"({"spec": "textures/slab.json", "generator": {}})"),
              where + "bodies[0].texture: takes 'spec' (a file) or 'generator' (the spec itself), not both");
    EXPECT_EQ(with(R"({"tiles_per_metre": 5})"),
              where + "bodies[0].texture: needs 'spec' (a texture spec file) or 'generator' (the spec itself)");
    nlohmann::json bad = nlohmann::json::parse(textureSpec(maps));
    bad["patterns"][0]["opacity"] = {0.5, 2};
    EXPECT_EQ(with("{\"generator\": " + bad.dump() + "}"),
              where + "bodies[0].texture.generator: patterns[0].opacity[1]: must be in [0, 1]");
    bad = nlohmann::json::parse(textureSpec(maps));
    bad["patterns"][0]["tile"] = {{"shape", "image"}, {"file", "../../etc/passwd"}};
    EXPECT_THAT(with("{\"generator\": " + bad.dump() + "}"),
                HasSubstr("bodies[0].texture.generator: patterns[0].tile.file: '../../etc/passwd' escapes"));
}

TEST_F(ProjectTest, SixteenBitMapsDecodeToTheSameCodesAsEightBitOnes) {
    // a 16-bit normal or roughness map is data, not light: the player's decoder rounds the
    // samples (no sRGB re-encoding), so it matches the 8-bit map of the same spec to one code
    std::filesystem::create_directories(m_dir / "textures");
    auto decodeWith = [&](int bits) {
        writeFileAtomic(m_dir / "textures/slab.json",
                        textureSpec(R"({"diffuse": {"colors": [0, 1], "bit_depth": )" + std::to_string(bits) +
                                    R"(}, "roughness": {"values": [0.9, 0.1], "bit_depth": )" + std::to_string(bits) +
                                    "}}"));
        write(replaced(kGood, "\"fixed\":", "\"texture\": {\"spec\": \"textures/slab.json\"}, \"fixed\":"));
        const studio::ProjectTextures t = studio::bakeProjectTextures(studio::loadProject(m_dir));
        return render::loadMaterialMaps(
            t.materials.at(0),
            [&](const std::string& f) -> std::string_view {
                for (const auto& [path, bytes] : t.files)
                    if (path == f) return bytes;
                return {};
            },
            "t");
    };
    const auto m8 = decodeWith(8), m16 = decodeWith(16);
    ASSERT_EQ(m8->roughness.rgba.size(), m16->roughness.rgba.size());
    int worst = 0;
    for (size_t i = 0; i < m8->roughness.rgba.size(); ++i) {
        worst = std::max(worst, std::abs(int(m8->roughness.rgba[i]) - int(m16->roughness.rgba[i])));
        worst = std::max(worst, std::abs(int(m8->diffuse.rgba[i]) - int(m16->diffuse.rgba[i])));
    }
    EXPECT_LE(worst, 1) << "codes";
}

TEST_F(ProjectTest, FileReferencesStayInsideTheProjectFolderThroughLinks) {
    namespace fs = std::filesystem;
    const fs::path outside = m_dir.string() + "_outside";
    fs::create_directories(outside);
    struct Cleanup {
        fs::path dir;
        ~Cleanup() { fs::remove_all(dir); }
    } cleanup{outside};
    const std::string where = (m_dir / "project.json").string() + ": ";
    // A mesh file and a texture spec that are links to files outside the folder are refused at load.
    writeFileAtomic(outside / "cube.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    fs::create_symlink(outside / "cube.obj", m_dir / "cube.obj");
    write(replaced(kGood, R"("mesh": {"generator": "box", "size": [0.04, 0.01, 0.01], "cells": [4, 1, 1]})",
                   R"("mesh": {"file": "cube.obj"})"));
    EXPECT_EQ(loadError(), where + "bodies[0].mesh.file: '" + (m_dir / "cube.obj").string() +
                               "' leads outside the project folder (to '" +
                               fs::canonical(outside / "cube.obj").string() + "'); project files must lie inside it");
    fs::create_directories(outside / "textures");
    writeFileAtomic(outside / "textures" / "t.json", "{}");
    fs::create_directory_symlink(outside / "textures", m_dir / "textures"); // a linked folder, too
    write(replaced(kGood, "\"fixed\":", R"("texture": {"spec": "textures/t.json"}, "fixed":)"));
    EXPECT_THAT(loadError(), HasSubstr(where + "bodies[0].texture.spec: '" + (m_dir / "textures/t.json").string() +
                                       "' leads outside the project folder"));
}

TEST_F(ProjectTest, ATrackThatLeadsOutsideOrIsAFifoIsRefusedAtLoad) {
    namespace fs = std::filesystem;
    const fs::path sample = fs::path(VISCERA_SOURCE_DIR) / "projects" / "rectum";
    fs::copy(sample / "project.json", m_dir / "project.json");
    fs::copy(sample / "tools", m_dir / "tools");
    ASSERT_EQ(loadError(), "accepted");
    const std::string where = (m_dir / "project.json").string() + ": ";
    const fs::path track = m_dir / "tools" / "hook.track", outside = m_dir.string() + "_hook.track";
    fs::rename(track, outside);
    struct Cleanup {
        fs::path file;
        ~Cleanup() { fs::remove(file); }
    } cleanup{outside};
    fs::create_symlink(outside, track);
    EXPECT_EQ(loadError(), where + "interaction.instruments[1].track: '" + track.string() +
                               "' leads outside the project folder (to '" + outside.string() +
                               "'); project files must lie inside it");
    fs::remove(track);
    ASSERT_EQ(::mkfifo(track.c_str(), 0600), 0);
    EXPECT_EQ(loadError(), track.string() + ": is not a regular file (a FIFO)"); // at once: nothing writes to it
}

TEST_F(ProjectTest, ExportOverAnInputIsRefusedBeforeTheWork) {
    write(kGood);
    const std::string before = readFile(m_dir / "project.json");
    const studio::Project p = studio::loadProject(m_dir);
    try {
        studio::exportCase(p, m_dir / "project.json");
        FAIL() << "exported over project.json";
    } catch (const InputError& e) {
        EXPECT_EQ(std::string(e.what()), (m_dir / "project.json").string() +
                                             ": cannot write the case over the input '" +
                                             (m_dir / "project.json").string() + "'");
    }
    EXPECT_EQ(readFile(m_dir / "project.json"), before) << "the input is intact";
    EXPECT_EQ(studio::projectInputFiles(p), std::vector<std::filesystem::path>{m_dir / "project.json"});
}

namespace {

// [issue 57 item 7] A tet mesh file (.msh) is a body's mesh as it is: read with its scale, no
// meshing settings (refused, naming the field), built without CGAL's mesher.
TEST_F(ProjectTest, ATetMeshFileIsABodysMeshAsItIs) {
    writeFileAtomic(m_dir / "two.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n5\n1 0 0 -1\n2 1 0 0\n"
                                       "3 0 1 0\n4 0 0 0\n5 0 0 1\n$EndNodes\n$Elements\n2\n"
                                       "1 4 0 1 2 3 4\n2 4 0 5 2 3 4\n$EndElements\n");
    const std::string box = R"("mesh": {"generator": "box", "size": [0.04, 0.01, 0.01], "cells": [4, 1, 1]})";
    write(replaced(kGood, box, R"("mesh": {"file": "two.msh", "scale": 0.01})"));
    ASSERT_EQ(loadError(), "accepted");
    const studio::Project p = studio::loadProject(m_dir);
    const auto mesh = studio::buildBodyMesh(p.bodies[0], "project.json", nullptr, m_dir);
    EXPECT_EQ(mesh->tets().size(), 2u);
    EXPECT_DOUBLE_EQ(mesh->positions()[0].cwiseAbs().maxCoeff(), 0.01);
    write(replaced(kGood, box, R"("mesh": {"file": "two.msh", "meshing": {"cell_size": 0.01}})"));
    EXPECT_THAT(loadError(), HasSubstr("bodies[0].mesh.meshing: unknown field"));
}

} // namespace
