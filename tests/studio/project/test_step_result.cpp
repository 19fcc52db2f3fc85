// The typed results of the studio's long steps [issue 57 item 6]: one reader and writer for the
// file a child hands back (round trip of every kind; each malformed field refused with the file,
// the field and the rule), and the kept remesh (Apply's surface reused by export, a changed
// block or part file not).
#include "project/remesh_cache.hpp"
#include "project/sample_kidney.hpp"
#include "project/step_result.hpp"
#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"
#include "support/scratch_dir.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fstream>

using namespace viscera;
using ::testing::HasSubstr;
using json = nlohmann::json;

namespace {

studio::BodyFigures body() {
    return {"anatomy", 812, 3120, 14, 11.5, 161.25, 0.21, 0.74, 0, 0, 3, 1.25e-4};
}

std::vector<studio::StepResult> samples() {
    studio::ImportStepResult i;
    i.parts.push_back({"/p/anatomy/cortex.obj", 812, 1620, false, true, {{{-0.05, -0.03, -0.02}, {0.05, 0.03, 0.02}}}});
    i.parts.push_back({"/p/anatomy/ureter.obj", 90, 160, true, false, {{{0, 0, 0}, {0.01, 0.01, 0.1}}}});
    studio::RemeshStepResult r;
    r.surface = "/p/.viscera-task-1/remesh.vremesh";
    r.cacheKey = std::string(64, 'a');
    r.vertices = 5120;
    r.triangles = 10236;
    r.closed = r.manifold = true;
    r.uvMethod = "seam-cut";
    r.uv = {{"closest", 12, 1.5, 0.002}, {"island", 3, 0.75, 0.001}, {"seam-cut", 0, 0.25, 0.0}};
    r.preview = "/p/.viscera-task-1/preview.png";
    r.seconds = 2.5;
    studio::MeshingStepResult m{body(), 10, 14, 1.9, true, 3.25, 14};
    studio::ExportStepResult e;
    e.casePath = "/out/case.vcase";
    e.bytes = 123456;
    e.sha256 = std::string(64, '0');
    e.keyId = "ed25519:abcd";
    e.signer = "publisher";
    e.features = {"xpbd", "uv"};
    e.bodies = {body()};
    e.remeshes = 1;
    e.seconds = 12;
    return {i, r, m, e};
}

/// The reader's error for the sample of `kind` with `edit` applied to its JSON ("accepted" when read).
std::string errorOf(size_t kind, const std::function<void(json&)>& edit) {
    json j = json::parse(studio::stepResultJson(samples()[kind]));
    edit(j);
    try {
        studio::parseStepResult(j.dump(), "r.json");
    } catch (const InputError& e) {
        return e.what();
    }
    return "accepted";
}

} // namespace

TEST(StepResult, EveryKindRoundTripsThroughTheOneReaderAndWriter) {
    for (const studio::StepResult& r : samples()) {
        const std::string text = studio::stepResultJson(r);
        EXPECT_EQ(studio::parseStepResult(text, "r.json"), r) << text;
        EXPECT_EQ(studio::stepResultJson(studio::parseStepResult(text, "r.json")), text);
    }
    test::Scratch scratch("viscera-step-result");
    const auto file = scratch.dir / "result.json";
    studio::writeStepResult(file, samples()[2]);
    EXPECT_EQ(studio::readStepResult<studio::MeshingStepResult>(file),
              std::get<studio::MeshingStepResult>(samples()[2]));
    try {
        studio::readStepResult<studio::RemeshStepResult>(file);
        ADD_FAILURE() << "a meshing result read as a remesh one";
    } catch (const InputError& e) {
        EXPECT_EQ(std::string(e.what()), file.string() + ": kind: must be 'remesh' (it is 'meshing')");
    }
}

TEST(StepResult, EachMalformedFieldIsRefusedNamingTheFieldAndTheRule) {
    EXPECT_EQ(errorOf(0, [](json& j) { j.erase("kind"); }), "r.json: kind: required field is missing");
    EXPECT_THAT(errorOf(0, [](json& j) { j["kind"] = "bake"; }), HasSubstr("r.json: kind: 'bake' is not one of"));
    EXPECT_EQ(errorOf(0, [](json& j) { j["extra"] = 1; }), "r.json: extra: unknown field");
    EXPECT_EQ(errorOf(0, [](json& j) { j["parts"] = json::array(); }), "r.json: parts: must not be empty");
    EXPECT_EQ(errorOf(0, [](json& j) { j["parts"][1]["file"] = "anatomy/u.obj"; }),
              "r.json: parts[1].file: must be an absolute path");
    EXPECT_EQ(errorOf(0, [](json& j) { j["parts"][0]["vertices"] = -3; }),
              "r.json: parts[0].vertices: must be a non-negative integer");
    EXPECT_EQ(errorOf(0, [](json& j) { j["parts"][0]["triangles"] = 1.5; }),
              "r.json: parts[0].triangles: must be a non-negative integer");
    EXPECT_THAT(errorOf(0, [](json& j) { j["parts"][0]["uv"] = "yes"; }), HasSubstr("r.json: parts[0].uv: must be"));
    EXPECT_EQ(errorOf(0, [](json& j) { j["parts"][0]["bounds"][0][0] = 1.0; }),
              "r.json: parts[0].bounds: the minimum must not exceed the maximum");
    EXPECT_THAT(errorOf(0,
                        [](json& j) {
                            j["parts"][0]["bounds"] = json::array({json::array({0, 0, 0})});
                        }),
                HasSubstr("r.json: parts[0].bounds: must have 2 elements"));
    EXPECT_EQ(errorOf(1, [](json& j) { j["cache_key"] = "XYZ"; }),
              "r.json: cache_key: must be empty or 64 lowercase hex characters (a sha256)");
    EXPECT_THAT(errorOf(1, [](json& j) { j["uv_method"] = "planar"; }),
                HasSubstr("r.json: uv_method: 'planar' is not one of"));
    EXPECT_THAT(errorOf(1, [](json& j) { j["uv"][2]["over_threshold_pct"] = 140; }),
                HasSubstr("r.json: uv[2].over_threshold_pct: must be in [0, 100]"));
    EXPECT_THAT(errorOf(1, [](json& j) { j["seconds"] = -1; }), HasSubstr("r.json: seconds: must not be negative"));
    EXPECT_EQ(errorOf(1, [](json& j) { j["preview"] = "p.png"; }), "r.json: preview: must be an absolute path");
    EXPECT_EQ(errorOf(2, [](json& j) { j["body"].erase("tets"); }), "r.json: body.tets: required field is missing");
    EXPECT_THAT(errorOf(2, [](json& j) { j["body"]["min_dihedral_deg"] = 200; }),
                HasSubstr("r.json: body.min_dihedral_deg: must be in [0, 180]"));
    EXPECT_THAT(errorOf(2, [](json& j) { j["required_substeps"] = 0; }), HasSubstr("r.json: required_substeps:"));
    EXPECT_THAT(errorOf(2, [](json& j) { j["remesh_reused"] = 1; }), HasSubstr("r.json: remesh_reused: must be"));
    EXPECT_EQ(errorOf(3, [](json& j) { j["sha256"] = "abc"; }), "r.json: sha256: must be 64 lowercase hex characters");
    EXPECT_EQ(errorOf(3, [](json& j) { j["signer"] = ""; }),
              "r.json: signer: must be given exactly when key_id is (a signed case names both)");
    EXPECT_THAT(errorOf(3, [](json& j) { j["features"][1] = ""; }), HasSubstr("r.json: features[1]:"));
    EXPECT_EQ(errorOf(3, [](json& j) { j["bodies"][0]["slivers"] = "3"; }),
              "r.json: bodies[0].slivers: must be a non-negative integer");
    EXPECT_EQ(errorOf(3, [](json&) {}), "accepted");
    try {
        studio::parseStepResult("{\"kind\": \"import\",", "r.json");
        ADD_FAILURE() << "truncated JSON accepted";
    } catch (const InputError& e) {
        EXPECT_THAT(e.what(), HasSubstr("r.json: invalid JSON"));
    }
}

TEST(KeptRemesh, TheKeyFollowsTheBlockAndThePartBytesAndTheFileRoundTripsExactly) {
    test::Scratch scratch("viscera-kept-remesh");
    const studio::Project p = studio::writeKidneySample(scratch.dir / "kidney");
    studio::RemeshSource block = p.bodies.at(0).mesh.remesh;
    const std::string key = studio::remeshKey(block);
    EXPECT_EQ(key.size(), 64u);
    EXPECT_EQ(studio::remeshKey(block), key) << "the same block and files, the same key";
    studio::RemeshSource other = block;
    other.params.voxelCount += 8;
    EXPECT_NE(studio::remeshKey(other), key) << "a changed remesh block";
    other = block;
    other.placement.scale = 2;
    EXPECT_NE(studio::remeshKey(other), key) << "a changed placement";
    other = block;
    other.texture.clear();
    EXPECT_EQ(studio::remeshKey(other), key) << "the texture does not shape the surface";
    {
        std::ofstream f(block.parts[0].file, std::ios::app);
        f << "# touched\n";
    }
    EXPECT_NE(studio::remeshKey(block), key) << "a changed part file";

    studio::RemeshedSurface s;
    s.hull = sim::TriMesh::fromArrays({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}},
                                      {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}}, "tet");
    s.surface = s.hull;
    s.uv.assign(4, {Eigen::Vector2d(0.1, 0.2), Eigen::Vector2d(1.0 / 3, 0.5), Eigen::Vector2d(0.9, 1e-17)});
    const auto file = scratch.dir / "s.vremesh";
    studio::writeRemeshedSurface(file, s);
    const studio::RemeshedSurface back = studio::readRemeshedSurface(file);
    EXPECT_EQ(back.hull.positions(), s.hull.positions());
    EXPECT_EQ(back.surface.triangles(), s.surface.triangles());
    ASSERT_EQ(back.uv.size(), 4u);
    EXPECT_EQ(back.uv[3][1], s.uv[3][1]) << "exact doubles";
    std::string bytes = readFile(file);
    writeFileAtomic(file, bytes.substr(0, bytes.size() - 5));
    EXPECT_THROW(
        {
            try {
                studio::readRemeshedSurface(file);
            } catch (const InputError& e) {
                EXPECT_THAT(e.what(), HasSubstr(file.string() + ": truncated at byte"));
                throw;
            }
        },
        InputError);
}

TEST(KeptRemesh, ExportAfterApplyReadsTheKeptSurfaceInsteadOfRemeshingAndMeshesTheSame) {
    test::Scratch scratch("viscera-kept-remesh-export");
    studio::Project p = studio::writeKidneySample(scratch.dir / "kidney");
    studio::BodyProject& b = p.bodies.at(0);
    b.mesh.remesh.params.voxelCount = 32; // small and quick
    b.mesh.meshing.cellSize = 0.012;
    b.mesh.meshing.facetSize = 0.009;
    const std::string origin = (p.dir / "project.json").string();
    // No kept surface: buildBodyMesh remeshes.
    uint64_t runs = studio::remeshRunCount();
    const auto fresh = studio::buildBodyMesh(b, origin, nullptr, p.dir);
    EXPECT_EQ(studio::remeshRunCount(), runs + 1);
    // What Apply keeps: the block's surface under its key.
    const studio::RemeshedSurface s = studio::remeshSurface(b.mesh.remesh);
    studio::writeRemeshedSurface(studio::keptRemeshFile(p.dir, studio::remeshKey(b.mesh.remesh)), s);
    runs = studio::remeshRunCount();
    bool reused = false;
    studio::keptOrFreshRemesh(b.mesh.remesh, p.dir, &reused);
    EXPECT_TRUE(reused);
    const auto kept = studio::buildBodyMesh(b, origin, nullptr, p.dir);
    EXPECT_EQ(studio::remeshRunCount(), runs) << "the kept surface is read, not remeshed";
    EXPECT_EQ(kept->positions(), fresh->positions()) << "the same mesh";
    EXPECT_EQ(kept->tets(), fresh->tets());
    // A changed block misses the kept file and remeshes.
    b.mesh.remesh.params.smoothingIterations = 1;
    studio::keptOrFreshRemesh(b.mesh.remesh, p.dir, &reused);
    EXPECT_FALSE(reused);
    EXPECT_EQ(studio::remeshRunCount(), runs + 1);
}
