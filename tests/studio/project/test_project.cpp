#include "case/case_package.hpp"
#include "project/project.hpp"
#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>

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
    // painted by the same strokes. The rectum's fat (box) and vessel (hollow tube), each meshed
    // two ways: at least 99 % of the painted mass is kept (and it does not grow by more than the
    // discretization can explain, 5 %: the poly6 field is sampled at other nodes).
    studio::Project p = studio::loadProject(std::filesystem::path(VISCERA_SOURCE_DIR) / "projects/rectum");
    p.dir = m_dir;
    ASSERT_GE(p.bodies.size(), 2u);
    studio::BodyProject& fat = p.bodies[0];
    studio::BodyProject& vessel = p.bodies[1];
    ASSERT_TRUE(fat.paint.has_value());
    fat.paint->strokes.push_back({sim::Vec3(0.02, -0.01, -0.004), 0.025, 3.0});
    sim::BrushStroke mix{sim::Vec3(-0.03, 0.02, -0.004), 0.02, 0.7};
    mix.mode = sim::BrushMode::Mix;
    mix.target = 0.3;
    fat.paint->strokes.push_back(mix);
    const sim::Vec3 a = vessel.mesh.hollow.start, b = vessel.mesh.hollow.end;
    vessel.paint = studio::StiffnessPaintProject{};
    vessel.paint->strokes.push_back({0.5 * (a + b), 0.015, 4.0});
    vessel.paint->strokes.push_back({0.8 * a + 0.2 * b, 0.01, -0.5});

    studio::Project q = p;
    q.bodies[0].mesh.box.cells = {48, 40, 3};
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
