// viscera-studio export --project-file: the project text comes from another file, its file
// references resolve against <project-dir>; the progress lines on stderr are numbered stages.
// viscera-studio texture <spec.json> -o <dir>: the files it writes and lists, one-line refusals.
#include "case/case_package.hpp"
#include "project/remesh_cache.hpp"
#include "project/sample_kidney.hpp"
#include "project/step_result.hpp"
#include "sim/util/atomic_file.hpp"
#include "support/case_signing.hpp"
#include "support/run_process.hpp"
#include "support/scratch_dir.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

using namespace viscera;
using ::testing::HasSubstr;
namespace fs = std::filesystem;

namespace {

test::ProcessResult runStudio(const std::vector<std::string>& args) {
    return test::runProcess(VISCERA_STUDIO_EXE, test::signingWithSampleKey(args));
}

std::vector<std::string> lines(const std::string& text) {
    std::vector<std::string> out;
    std::istringstream in(text);
    for (std::string l; std::getline(in, l);)
        out.push_back(l);
    return out;
}

const char* kProject = R"({
  "schemaVersion": 1, "caseId": "cube", "caseVersion": "1.0.0", "title": "From the project file",
  "solver": {"type": "xpbd", "substeps": 100},
  "bodies": [{"name": "cube",
              "mesh": {"file": "meshes/cube.obj", "scale": 0.001,
                       "meshing": {"cell_size": 0.004, "facet_size": 0.004, "seed": 1}},
              "material": {"model": "stable_neo_hookean", "youngs_modulus": 20000, "poisson_ratio": 0.4,
                           "density": 1000},
              "fixed": {"min": [-1, -1, -1], "max": [0.0001, 1, 1]}}]
})";

} // namespace

TEST(StudioCli, ExportReadsTheProjectFileAndNumbersItsStages) {
    test::Scratch scratch("viscera-studio-cli");
    // The project folder holds the mesh but no project.json; the text lies elsewhere.
    const fs::path dir = scratch.dir / "project";
    writeFileAtomic(dir / "meshes" / "cube.obj",
                    "v 0 0 0\nv 10 0 0\nv 0 10 0\nv 10 10 0\nv 0 0 10\nv 10 0 10\nv 0 10 10\nv 10 10 10\n"
                    "f 1 3 4\nf 1 4 2\nf 5 6 8\nf 5 8 7\nf 1 2 6\nf 1 6 5\nf 3 7 8\nf 3 8 4\nf 1 5 7\nf 1 7 3\n"
                    "f 2 4 8\nf 2 8 6\n");
    const fs::path text = scratch.dir / "unsaved" / "edit.json";
    writeFileAtomic(text, kProject);
    const fs::path out = scratch.dir / "cube.vcase";
    auto r = runStudio({"export", dir.string(), "-o", out.string(), "--project-file", text.string()});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_THAT(r.out, HasSubstr("exported cube -> "));
    EXPECT_EQ(vcase::CasePackage::open(out)->manifest().title.value_or(""), "From the project file");
    const std::vector<std::string> progress = lines(r.err);
    const std::regex stage(R"(viscera-studio: stage (\d+)/3: .+)");
    ASSERT_EQ(progress.size(), 3u) << r.err;
    for (size_t i = 0; i < progress.size(); ++i) {
        std::smatch m;
        ASSERT_TRUE(std::regex_match(progress[i], m, stage)) << progress[i];
        EXPECT_EQ(m[1].str(), std::to_string(i + 1));
    }
    EXPECT_EQ(progress[0], "viscera-studio: stage 1/3: meshing body 'cube'");

    // Errors name the project file that was given; without it, <project-dir>/project.json is read.
    writeFileAtomic(text, "{");
    auto bad = runStudio({"export", dir.string(), "-o", out.string(), "--project-file", text.string()});
    EXPECT_EQ(bad.exitCode, 1);
    EXPECT_THAT(bad.err, HasSubstr(text.string() + ": invalid JSON"));
    auto none = runStudio({"export", dir.string(), "-o", out.string()});
    EXPECT_EQ(none.exitCode, 1);
    EXPECT_THAT(none.err, HasSubstr((dir / "project.json").string() + ": cannot open for reading"));
    auto usage = runStudio({"export", dir.string(), "-o", out.string(), "--project-file"});
    EXPECT_EQ(usage.exitCode, 2);
    EXPECT_THAT(usage.err, HasSubstr("--project-file needs a value"));
}

namespace {

/// The headless commands need no display: no DISPLAY, WAYLAND_DISPLAY or QT_QPA_PLATFORM.
void withoutDisplay() {
    ::unsetenv("DISPLAY");
    ::unsetenv("WAYLAND_DISPLAY");
    ::unsetenv("QT_QPA_PLATFORM");
}

} // namespace

TEST(StudioCli, ExportRunsWithoutADisplayOrQtPlatform) {
    withoutDisplay();
    test::Scratch s("viscera-studio-cli");
    const std::string out = s / "slab.vcase";
    const auto r = runStudio({"export", std::string(VISCERA_SOURCE_DIR) + "/projects/tissue-slab", "-o", out});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_THAT(r.out, HasSubstr("exported tissue-slab"));
    EXPECT_NO_THROW(vcase::verify(out));
}

TEST(StudioCli, TheWindowWithoutADisplayIsRefusedWithOneLine) {
    withoutDisplay();
    for (const std::vector<std::string>& args :
         {std::vector<std::string>{}, {"open", std::string(VISCERA_SOURCE_DIR) + "/projects/liver"}}) {
        const auto r = runStudio(args);
        EXPECT_EQ(r.exitCode, 1);
        const auto l = lines(r.err);
        ASSERT_EQ(l.size(), 1u) << r.err;
        EXPECT_THAT(l[0], HasSubstr("no display"));
    }
    const auto help = runStudio({"--help"});
    EXPECT_EQ(help.exitCode, 0);
    EXPECT_THAT(help.out, HasSubstr("open <project-dir>"));
}

namespace {

/// A texture spec: one patterned level, an explicit palette, four maps.
const char* kSpec = R"({
  "size": 64, "seed": 3, "levels": 5,
  "patterns": [{"level": 3, "tile": {"shape": "gaussian"}, "offset": {"radius": [0, 0.5]},
                "scale": {"uniform": [0.8, 1.5]}, "opacity": [0.5, 1]}],
  "palette": {"colors": ["#7a1f24", "#efc1a8"]},
  "maps": {"diffuse": {}, "roughness": {"values": [0.6, 0.3]}, "height": {}, "normal": {"bit_depth": 16}}
})";

} // namespace

TEST(StudioCli, TextureWritesTheMapsOfASpecAndListsThem) {
    test::Scratch scratch("viscera-studio-texture");
    const fs::path spec = scratch.dir / "mucosa.json";
    writeFileAtomic(spec, kSpec);
    const fs::path out = scratch.dir / "maps";
    const auto r = runStudio({"texture", spec.string(), "-o", out.string()});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_THAT(r.out, HasSubstr("texture mucosa: 64x64, 5 levels, 1 patterns, seed 3, tileable"));
    EXPECT_THAT(r.out, HasSubstr("palette: #7a1f24 #efc1a8"));
    for (const char* map : {"diffuse", "roughness", "height", "normal"}) {
        const fs::path file = out / (std::string("mucosa_") + map + ".png");
        ASSERT_TRUE(fs::is_regular_file(file)) << file;
        EXPECT_THAT(r.out,
                    HasSubstr("wrote " + file.string() + " (" + std::to_string(fs::file_size(file)) + " bytes)"));
    }
    EXPECT_FALSE(fs::exists(out / "mucosa_mask.png"));
    EXPECT_THAT(r.out, HasSubstr("time: load "));
    EXPECT_TRUE(r.err.empty()) << r.err;

    // A bad spec: exit 1 and one line naming the file, the field and the rule.
    std::string bad = kSpec;
    bad.replace(bad.find("\"levels\": 5"), 11, "\"levels\": 5, \"colour\": 1");
    writeFileAtomic(spec, bad);
    const auto refused = runStudio({"texture", spec.string(), "-o", out.string()});
    EXPECT_EQ(refused.exitCode, 1);
    EXPECT_EQ(refused.err, "viscera-studio: " + spec.string() + ": colour: unknown field\n");
    // Usage errors: exit 2; the usage text lists the command.
    const auto usage = runStudio({"texture", spec.string()});
    EXPECT_EQ(usage.exitCode, 2);
    EXPECT_THAT(usage.err, HasSubstr("texture needs <spec.json> and -o <dir>"));
    EXPECT_THAT(runStudio({"--help"}).out, HasSubstr("viscera-studio texture <spec.json> -o <dir>"));
}

// import --tetrahedralize: an output it cannot write is refused before meshing (no stage line),
// meshing reports its stages on stderr, a reference out of the folder is refused in one line.
TEST(StudioCli, ImportChecksItsOutputFirstAndReportsMeshingStages) {
    test::Scratch s("viscera-studio-cli");
    const std::string obj = s / "cube.obj";
    writeFileAtomic(obj, "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
                         "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n");
    writeFileAtomic(s / "file", "x");
    const auto refused =
        runStudio({"import", obj, "--tetrahedralize", "-o", (fs::path(s / "file") / "cube.vtet").string()});
    EXPECT_EQ(refused.exitCode, 1);
    EXPECT_THAT(refused.err, HasSubstr("cube.vtet: cannot write the tet mesh"));
    EXPECT_THAT(refused.err, ::testing::Not(HasSubstr("meshing:")));
    EXPECT_EQ(lines(refused.err).size(), 1u) << refused.err;

    const auto r = runStudio({"import", obj, "--tetrahedralize", "-o", s / "cube.vtet"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_THAT(r.err, HasSubstr("viscera-studio: meshing: check surface (0%)"));
    EXPECT_THAT(r.err, HasSubstr("viscera-studio: meshing: refine ("));
    EXPECT_THAT(r.err, HasSubstr("viscera-studio: meshing: export (100%)"));
    EXPECT_TRUE(fs::exists(s / "cube.vtet"));

    writeFileAtomic(s / "up.obj", "mtllib ../outside.mtl\n" + readFile(obj));
    const auto up = runStudio({"import", s / "up.obj"});
    EXPECT_EQ(up.exitCode, 1);
    EXPECT_THAT(up.err, HasSubstr("up.obj: line 1: mtllib '../outside.mtl': leaves the file's folder"));
    EXPECT_EQ(lines(up.err).size(), 1u) << up.err;
}

TEST(StudioCli, TheUvMethodWrittenIsChosenAndAnUnknownOneIsRefusedByName) {
    test::Scratch s("viscera-studio-cli-gl");
    auto r = test::runProcess(VISCERA_STUDIO_EXE, {"remesh", "--sample", "kidney", "--voxels", "40", "--uv-transfer",
                                                   "closest", "-o", s / "closest.obj"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_THAT(r.out, HasSubstr("uv.written closest\n"));
    EXPECT_THAT(readFile(s / "closest.obj"), HasSubstr("\nvt "));
    r = test::runProcess(VISCERA_STUDIO_EXE,
                         {"remesh", "--sample", "kidney", "--uv-transfer", "nearest", "-o", s / "bad.obj"});
    EXPECT_NE(r.exitCode, 0);
    EXPECT_THAT(r.err, HasSubstr("--uv-transfer 'nearest': the methods are seam-cut, closest and island"));
    EXPECT_FALSE(fs::exists(s / "bad.obj"));
}

// --result [issue 57 item 6]: import, mesh, remesh --body and export each hand back a typed result
// file (project/step_result.hpp) the studio reads instead of their text; mesh meshes one body
// and writes no case.
TEST(StudioCli, ImportMeshRemeshAndExportWriteTheirTypedResults) {
    test::Scratch scratch("viscera-studio-cli-result");
    const fs::path dir = scratch.dir / "project";
    writeFileAtomic(dir / "meshes" / "cube.obj",
                    "v 0 0 0\nv 10 0 0\nv 0 10 0\nv 10 10 0\nv 0 0 10\nv 10 0 10\nv 0 10 10\nv 10 10 10\n"
                    "f 1 3 4\nf 1 4 2\nf 5 6 8\nf 5 8 7\nf 1 2 6\nf 1 6 5\nf 3 7 8\nf 3 8 4\nf 1 5 7\nf 1 7 3\n"
                    "f 2 4 8\nf 2 8 6\n");
    writeFileAtomic(dir / "project.json", kProject);

    auto r = runStudio({"import", (dir / "meshes" / "cube.obj").string(), "--result", scratch / "import.json"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto imported = studio::readStepResult<studio::ImportStepResult>(scratch / "import.json");
    ASSERT_EQ(imported.parts.size(), 1u);
    EXPECT_EQ(imported.parts[0].file, (dir / "meshes" / "cube.obj").string());
    EXPECT_EQ(imported.parts[0].vertices, 8);
    EXPECT_EQ(imported.parts[0].triangles, 12);
    EXPECT_TRUE(imported.parts[0].closed);
    EXPECT_EQ(imported.parts[0].bounds[1][0], 10.0) << "file units";

    r = test::runProcess(VISCERA_STUDIO_EXE,
                         {"mesh", dir.string(), "--body", "cube", "--result", scratch / "mesh.json"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(lines(r.err), (std::vector<std::string>{"viscera-studio: stage 1/2: meshing body 'cube'",
                                                      "viscera-studio: stage 2/2: checking body 'cube'"}));
    const auto meshed = studio::readStepResult<studio::MeshingStepResult>(scratch / "mesh.json");
    EXPECT_EQ(meshed.body.name, "cube");
    EXPECT_GT(meshed.body.tets, 20); // CGAL's mesh of the 1 cm cube at the block's cell size
    EXPECT_GT(meshed.body.fixedNodes, 0);
    EXPECT_EQ(meshed.body.inverted, 0);
    EXPECT_EQ(meshed.substeps, 100);
    EXPECT_GT(meshed.stiffnessNumber, 0);
    EXPECT_FALSE(meshed.remeshReused);
    for (const auto& e : fs::recursive_directory_iterator(scratch.dir))
        EXPECT_NE(e.path().extension(), ".vcase") << "meshing writes no case: " << e.path();
    auto unknown = test::runProcess(VISCERA_STUDIO_EXE, {"mesh", dir.string(), "--body", "sphere"});
    EXPECT_EQ(unknown.exitCode, 1);
    EXPECT_THAT(unknown.err, HasSubstr("project.json: bodies: no body named 'sphere'"));

    const fs::path out = scratch.dir / "cube.vcase";
    r = runStudio({"export", dir.string(), "-o", out.string(), "--result", scratch / "export.json"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto exported = studio::readStepResult<studio::ExportStepResult>(scratch / "export.json");
    EXPECT_EQ(exported.casePath, fs::absolute(out).string());
    EXPECT_EQ(uint64_t(exported.bytes), fs::file_size(out));
    EXPECT_EQ(exported.sha256, vcase::CasePackage::open(out)->sha256());
    ASSERT_EQ(exported.bodies.size(), 1u);
    EXPECT_EQ(exported.bodies[0].tets, meshed.body.tets) << "mesh meshes the body as export does";
    EXPECT_FALSE(exported.keyId.empty()) << "signed with the sample key";
    EXPECT_EQ(exported.remeshes, 0) << "no remesh block";

    // remesh --body: the block of a project body, remeshed as export remeshes it; the settings
    // are the block's, so none is taken on the command line.
    const fs::path kidney = scratch.dir / "kidney";
    studio::writeKidneySample(kidney);
    auto refused = test::runProcess(VISCERA_STUDIO_EXE, {"remesh", "--project", kidney.string(), "--body", "kidney",
                                                         "--voxels", "40", "-o", scratch / "k.vremesh"});
    EXPECT_EQ(refused.exitCode, 2);
    EXPECT_THAT(refused.err, HasSubstr("remesh --body: --voxels: the settings are the body's remesh block"));
    r = test::runProcess(VISCERA_STUDIO_EXE, {"remesh", "--project", kidney.string(), "--body", "kidney", "-o",
                                              scratch / "k.vremesh", "--result", scratch / "remesh.json"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto remeshed = studio::readStepResult<studio::RemeshStepResult>(scratch / "remesh.json");
    const studio::Project kp = studio::loadProject(kidney);
    EXPECT_EQ(remeshed.cacheKey, studio::remeshKey(kp.bodies[0].mesh.remesh));
    EXPECT_EQ(remeshed.surface, (scratch.dir / "k.vremesh").string());
    EXPECT_TRUE(remeshed.closed && remeshed.manifold);
    EXPECT_EQ(remeshed.uvMethod, "seam-cut");
    EXPECT_EQ(remeshed.uv.size(), 3u);
    EXPECT_EQ(studio::readRemeshedSurface(scratch / "k.vremesh").surface.triangleCount(), size_t(remeshed.triangles));
}

/// `import` of the parts <dir>/<name>.obj reads each back with UVs, closed or open as given.
void expectImported(const test::Scratch& scratch, const fs::path& dir, const std::vector<std::string>& names,
                    const std::vector<bool>& closed) {
    std::vector<std::string> args = {"import"};
    for (const std::string& part : names)
        args.push_back((dir / (part + ".obj")).string());
    args.push_back("--result");
    args.push_back(std::string(scratch / "import.json"));
    const auto r = runStudio(args);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto imported = studio::readStepResult<studio::ImportStepResult>(scratch / "import.json");
    ASSERT_EQ(imported.parts.size(), names.size());
    for (size_t i = 0; i < names.size(); ++i) {
        EXPECT_EQ(imported.parts[i].closed, closed[i]) << imported.parts[i].file;
        EXPECT_TRUE(imported.parts[i].hasUv) << imported.parts[i].file;
    }
}

// `sample hepatocystic` [issue 57 item 4]: the cholecystectomy's anatomy written as bought anatomy
// arrives (five OBJ parts with UVs and their atlas, no project), read back by `import` as the
// studio reads it: the liver and the ducts open, the gallbladder and the artery closed, all with UVs.
TEST(StudioCli, TheHepatocysticSampleIsAnatomyToImport) {
    test::Scratch scratch("viscera-studio-cli-hepatocystic");
    const fs::path dir = scratch.dir / "anatomy";
    auto r = runStudio({"sample", "hepatocystic", "-o", dir.string()});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_THAT(r.out, HasSubstr("wrote 5 anatomy parts and the atlas hepatocystic.png"));
    EXPECT_FALSE(fs::exists(dir / "project.json")) << "the case is built in the studio";
    EXPECT_TRUE(fs::exists(dir / "hepatocystic.png"));
    ASSERT_NO_FATAL_FAILURE(expectImported(scratch, dir,
                                           {"liver", "gallbladder", "cystic_duct", "common_bile_duct", "cystic_artery"},
                                           {false, true, false, false, true}));
    r = runStudio({"sample", "spleen", "-o", dir.string()});
    EXPECT_NE(r.exitCode, 0);
    EXPECT_THAT(r.err, HasSubstr("'rectum -o <folder>' (the built-in samples)"));
}

// `sample rectum` [issue 57 item 5]: the rectum's anatomy the same way (four OBJ parts with UVs, no
// atlas, no project); `import` reads the mesorectum closed and the other three open, all with UVs.
TEST(StudioCli, TheRectumSampleIsAnatomyToImport) {
    test::Scratch scratch("viscera-studio-cli-rectum");
    const fs::path dir = scratch.dir / "anatomy";
    auto r = runStudio({"sample", "rectum", "-o", dir.string()});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_THAT(r.out, HasSubstr("wrote 4 anatomy parts into"));
    EXPECT_FALSE(fs::exists(dir / "project.json"));
    ASSERT_NO_FATAL_FAILURE(expectImported(scratch, dir, {"mesorectum", "rectum", "pelvic_wall", "peritoneum"},
                                           {true, false, false, false}));
}
