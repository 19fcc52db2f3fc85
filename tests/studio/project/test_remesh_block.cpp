// The "remesh" mesh block of project.json [issue 38 item 2] and the kidney sample made by code
// [item 4]: the sample round-trips through the one reader and writer; every field's rule names
// the field; the export remeshes the parts, transfers their UVs onto the tet boundary and
// packages them with the texture (render.materials.<body>: diffuse + uv).
#include "case/case_package.hpp"
#include "project/project.hpp"
#include "project/sample_kidney.hpp"
#include "render/case_settings.hpp"
#include "render/corner_uv.hpp"
#include "sim/mesh/tet_io.hpp"
#include "sim/scene/scene_json.hpp"
#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"
#include "support/scratch_dir.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <limits>

using namespace viscera;
using ::testing::HasSubstr;
using json = nlohmann::json;

namespace {

class RemeshBlock : public ::testing::Test {
protected:
    test::Scratch m_scratch{"viscera-remesh-block"};
    std::filesystem::path m_dir = m_scratch.dir / "kidney";

    /// The error of loading the sample's project.json with `edit` applied ("accepted" when it loads).
    std::string loadError(const std::function<void(json&)>& edit) {
        json doc = json::parse(readFile(m_dir / "project.json"));
        edit(doc["bodies"][0]["mesh"]["remesh"]);
        try {
            studio::loadProjectText(doc.dump(1), m_dir, (m_dir / "project.json").string());
        } catch (const InputError& e) {
            return e.what();
        }
        return "accepted";
    }
};

} // namespace

TEST_F(RemeshBlock, TheKidneySampleRoundTripsThroughTheOneReaderAndWriter) {
    const studio::Project p = studio::writeKidneySample(m_dir);
    ASSERT_EQ(p.bodies.size(), 1u);
    const studio::MeshSource& m = p.bodies[0].mesh;
    ASSERT_EQ(m.kind, studio::MeshSource::Kind::Remesh);
    ASSERT_EQ(m.remesh.parts.size(), 4u);
    EXPECT_EQ(m.remesh.parts[0].file, m_dir / "anatomy" / "cortex.obj");
    EXPECT_EQ(m.remesh.params.voxelCount, 64);
    EXPECT_EQ(m.remesh.uvTransfer, bake::UvTransferMethod::SeamCutting);
    EXPECT_EQ(m.remesh.texture, m_dir / "anatomy" / "kidney.png");
    const std::string text = readFile(m_dir / "project.json");
    EXPECT_EQ(studio::projectJsonText(p), text);
    // Every optional field set the other way survives the writer.
    json doc = json::parse(text);
    json& r = doc["bodies"][0]["mesh"]["remesh"];
    r.erase("voxel_count");
    r["voxel_size"] = 0.0015;
    r["edge_length"] = 0.002;
    r["smoothing"] = 2;
    r["fill_openings"] = 0.006;
    r["uv_transfer"] = "island";
    r["parts"][1]["op"] = "difference";
    const studio::Project q = studio::loadProjectText(doc.dump(1), m_dir, (m_dir / "project.json").string());
    const studio::RemeshSource& s = q.bodies[0].mesh.remesh;
    EXPECT_EQ(s.params.voxelSize, 0.0015);
    EXPECT_EQ(s.params.targetEdgeLength, 0.002);
    EXPECT_EQ(s.params.smoothingIterations, 2);
    EXPECT_EQ(s.params.fillOpenings, 0.006);
    EXPECT_EQ(s.uvTransfer, bake::UvTransferMethod::IslandLabelled);
    EXPECT_EQ(s.parts[1].op, bake::CsgOp::Difference);
    const std::string again = studio::projectJsonText(q);
    EXPECT_EQ(studio::projectJsonText(studio::loadProjectText(again, m_dir, "again")), again);
}

TEST_F(RemeshBlock, EveryFieldIsRefusedByNameAndRule) {
    studio::writeKidneySample(m_dir);
    const std::string at = "bodies[0].mesh.remesh.";
    EXPECT_THAT(loadError([](json& r) { r["parts"] = json::array(); }),
                HasSubstr(at + "parts: must be an array of 1 to 64 parts"));
    EXPECT_THAT(loadError([](json& r) { r["voxel_size"] = 0.001; }),
                HasSubstr("give voxel_size or voxel_count, not both"));
    EXPECT_THAT(loadError([](json& r) { r["voxel_count"] = 4; }), HasSubstr(at + "voxel_count"));
    EXPECT_THAT(loadError([](json& r) { r["smoothing"] = 101; }), HasSubstr(at + "smoothing"));
    EXPECT_THAT(loadError([](json& r) { r["iterations"] = -1; }), HasSubstr(at + "iterations"));
    EXPECT_THAT(loadError([](json& r) { r["fill_openings"] = 0; }), HasSubstr(at + "fill_openings"));
    EXPECT_THAT(loadError([](json& r) { r["fill_openings"] = 2; }), HasSubstr(at + "fill_openings"));
    EXPECT_THAT(loadError([](json& r) { r["scale"] = 0; }), HasSubstr(at + "scale"));
    EXPECT_THAT(loadError([](json& r) { r["uv_transfer"] = "nearest"; }), HasSubstr(at + "uv_transfer"));
    EXPECT_THAT(loadError([](json& r) { r["texture"] = "anatomy/kidney.jpg"; }),
                HasSubstr(at + "texture: must be a PNG image (.png)"));
    EXPECT_THAT(loadError([](json& r) { r["uv_transfer"] = "none"; }), HasSubstr(at + "texture: needs UVs"));
    EXPECT_THAT(loadError([](json& r) { r["parts"][0]["file"] = "../cortex.obj"; }), HasSubstr(at + "parts[0].file"));
    EXPECT_THAT(loadError([](json& r) { r["parts"][0]["op"] = "xor"; }), HasSubstr(at + "parts[0].op"));
    EXPECT_THAT(loadError([](json& r) { r["colour"] = 1; }), HasSubstr("colour"));
    // the meshing block beside it: the cap on the tets
    json doc = json::parse(readFile(m_dir / "project.json"));
    doc["bodies"][0]["mesh"]["meshing"]["max_tets"] = 10;
    try {
        studio::loadProjectText(doc.dump(1), m_dir, "project.json");
        ADD_FAILURE() << "max_tets 10 accepted";
    } catch (const InputError& e) {
        EXPECT_THAT(e.what(), HasSubstr("bodies[0].mesh.meshing.max_tets"));
    }
    doc["bodies"][0]["mesh"]["meshing"]["max_tets"] = 50000;
    const studio::Project capped = studio::loadProjectText(doc.dump(1), m_dir, "project.json");
    EXPECT_EQ(capped.bodies[0].mesh.meshing.maxEstimatedTets, 50000u);
    EXPECT_THAT(studio::projectJsonText(capped), HasSubstr("\"max_tets\": 50000"));
}

TEST_F(RemeshBlock, ExportLaysTheTextureOnTheTetBoundaryByTheTransferredUvs) {
    studio::writeKidneySample(m_dir);
    const studio::Project p = studio::loadProject(m_dir);
    const auto out = m_scratch.dir / "kidney.vcase";
    const studio::ExportResult r = studio::exportCase(p, out);
    ASSERT_EQ(r.bodies.size(), 1u);
    EXPECT_GT(r.bodies[0].tets, 500u);
    EXPECT_TRUE(r.bodies[0].quality.inverted.empty());
    EXPECT_TRUE(r.bodies[0].quality.slivers.empty());
    const auto pkg = vcase::CasePackage::open(out);
    ASSERT_TRUE(pkg->contains("meshes/kidney.vuv"));
    ASSERT_TRUE(pkg->contains("textures/kidney_diffuse.png"));
    EXPECT_EQ(pkg->read("textures/kidney_diffuse.png"), readFile(m_dir / "anatomy" / "kidney.png"));
    const sim::SceneDesc scene = sim::parseScene(pkg->read("scene.json"), "scene.json");
    const auto materials = render::caseMaterialMaps(scene.render, "scene.json");
    ASSERT_EQ(materials.size(), 1u);
    EXPECT_EQ(materials[0].uv, "meshes/kidney.vuv");
    EXPECT_EQ(materials[0].diffuse, "textures/kidney_diffuse.png");
    auto mesh = sim::parseVtet(pkg->read("meshes/kidney.vtet"), "kidney.vtet");
    mesh->requireLevel(3);
    const auto uv =
        render::parseCornerUv(pkg->read("meshes/kidney.vuv"), "kidney.vuv", mesh->boundary().triangleCount());
    // The UVs lie in the atlas (the sample's islands span [0.02, 0.98]²) and vary over the body.
    float lo = 1, hi = 0;
    for (const auto& c : uv)
        for (const auto& w : c) {
            EXPECT_GE(w.x(), 0.0f);
            EXPECT_LE(w.x(), 1.0f);
            lo = std::min(lo, w.x());
            hi = std::max(hi, w.x());
        }
    EXPECT_GT(hi - lo, 0.5f);
}

TEST_F(RemeshBlock, APartWithoutUvsIsRefusedAtExportNamingTheFile) {
    studio::writeKidneySample(m_dir);
    std::string obj = readFile(m_dir / "anatomy" / "artery.obj");
    std::string plain;
    for (size_t at = 0; at < obj.size();) { // drop the vt lines and the /vt of the faces
        const size_t end = obj.find('\n', at);
        std::string line = obj.substr(at, end - at);
        at = end == std::string::npos ? obj.size() : end + 1;
        if (line.rfind("vt ", 0) == 0) continue;
        if (line.rfind("f ", 0) == 0)
            for (size_t s = line.find('/'); s != std::string::npos; s = line.find('/')) {
                const size_t e = line.find(' ', s);
                line.erase(s, (e == std::string::npos ? line.size() : e) - s);
            }
        plain += line + "\n";
    }
    writeFileAtomic(m_dir / "anatomy" / "artery.obj", plain);
    const studio::Project p = studio::loadProject(m_dir);
    try {
        studio::exportCase(p, m_scratch.dir / "kidney.vcase");
        ADD_FAILURE() << "exported";
    } catch (const InputError& e) {
        EXPECT_THAT(e.what(), HasSubstr("artery.obj: has no texture coordinates"));
    }
    EXPECT_FALSE(std::filesystem::exists(m_scratch.dir / "kidney.vcase"));
}

// Issue 57 item 7: the parts' unit, uniform scale and rotation, read and written by the one reader;
// a centimetre file comes in at its size in metres, a Y-up one turned Z-up.
TEST_F(RemeshBlock, ThePartsUnitScaleAndRotationPlaceThemInMetres) {
    studio::writeKidneySample(m_dir);
    { // a 12 × 8 × 6 cm box, corner (1, 2, 3) cm, in centimetres
        std::string obj;
        for (int c = 0; c < 8; ++c)
            obj += "v " + std::string(c & 1 ? "13" : "1") + (c & 2 ? " 10" : " 2") + (c & 4 ? " 9" : " 3") + "\n";
        obj += "f 1 3 4\nf 1 4 2\nf 5 6 8\nf 5 8 7\nf 1 2 6\nf 1 6 5\nf 3 7 8\nf 3 8 4\nf 1 5 7\nf 1 7 3\nf 2 4 8\n"
               "f 2 8 6\n";
        writeFileAtomic(m_dir / "anatomy" / "box-cm.obj", obj);
    }
    json doc = json::parse(readFile(m_dir / "project.json"));
    json& r = doc["bodies"][0]["mesh"]["remesh"];
    EXPECT_EQ(r["unit"], "m") << "written explicitly, as every default";
    EXPECT_EQ(r["rotation_deg"], json::array({0, 0, 0}));
    r["parts"] = json::array({{{"file", "anatomy/box-cm.obj"}}});
    r["uv_transfer"] = "none";
    r.erase("texture");
    r["unit"] = "cm";
    r["scale"] = 2;
    r["rotation_deg"] = {90, 0, 0};
    const studio::Project p = studio::loadProjectText(doc.dump(1), m_dir, "project.json");
    const bake::ImportPlacement& q = p.bodies[0].mesh.remesh.placement;
    EXPECT_EQ(q.unit, bake::LengthUnit::Centimetre);
    EXPECT_EQ(q.scale, 2.0);
    EXPECT_EQ(q.rotationDeg, Eigen::Vector3d(90, 0, 0));
    EXPECT_DOUBLE_EQ(q.metresPerFileUnit(), 0.02);
    const std::string text = studio::projectJsonText(p);
    EXPECT_EQ(studio::loadProjectText(text, m_dir, "again").bodies[0].mesh.remesh.placement, q);
    // (x, y, z) cm × 2 → (x, −z, y) m: what export meshes (project.cpp imports every part so)
    const auto [lo, hi] = bake::importSurface(m_dir / "anatomy" / "box-cm.obj", bake::placedOptions(q)).bounds();
    EXPECT_LT((lo - sim::Vec3(0.02, -0.18, 0.04)).cwiseAbs().maxCoeff(), 1e-6) << lo.transpose();
    EXPECT_LT((hi - sim::Vec3(0.26, -0.06, 0.20)).cwiseAbs().maxCoeff(), 1e-6) << hi.transpose();
    bake::ImportPlacement plainCm;
    plainCm.unit = bake::LengthUnit::Centimetre;
    const auto [lo1, hi1] =
        bake::importSurface(m_dir / "anatomy" / "box-cm.obj", bake::placedOptions(plainCm)).bounds();
    EXPECT_LT((hi1 - lo1 - sim::Vec3(0.12, 0.08, 0.06)).cwiseAbs().maxCoeff(), 1e-6) << (hi1 - lo1).transpose();
}

TEST_F(RemeshBlock, ThePlacementsRulesNameTheFieldInTheFileAndOnAValue) {
    studio::writeKidneySample(m_dir);
    const std::string at = "bodies[0].mesh.remesh.";
    EXPECT_THAT(loadError([](json& r) { r["unit"] = "ft"; }),
                HasSubstr(at + "unit: 'ft' is not a length unit (m, cm, mm, inch)"));
    EXPECT_THAT(loadError([](json& r) { r["scale"] = -1; }), HasSubstr(at + "scale: must be positive"));
    EXPECT_THAT(loadError([](json& r) {
                    r["rotation_deg"] = {0, 400, 0};
                }),
                HasSubstr(at + "rotation_deg[1]: must be in [-360, 360]"));
    EXPECT_THAT(loadError([](json& r) {
                    r["rotation_deg"] = {90, 0};
                }),
                HasSubstr(at + "rotation_deg: must be an array of 3 numbers"));
    EXPECT_EQ(loadError([](json& r) { r["unit"] = "inch"; }), "accepted");
    // the same rule on a value (the studio's typed edit)
    bake::ImportPlacement q;
    EXPECT_EQ(studio::placementProblem(q, "bodies[2].mesh.remesh"), "");
    q.rotationDeg.z() = -361;
    EXPECT_EQ(studio::placementProblem(q, "bodies[2].mesh.remesh"),
              "bodies[2].mesh.remesh.rotation_deg[2]: must be in [-360, 360]");
    q.rotationDeg.z() = 0;
    q.scale = std::numeric_limits<double>::quiet_NaN();
    EXPECT_THAT(studio::placementProblem(q, "b"), HasSubstr("b.scale: must be"));
    // importSurface refuses what is not a rotation
    bake::ImportOptions skew;
    skew.rotation(0, 1) = 0.5;
    EXPECT_THROW(bake::importSurface(m_dir / "anatomy" / "cortex.obj", skew), std::invalid_argument);
}
