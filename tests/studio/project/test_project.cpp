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
