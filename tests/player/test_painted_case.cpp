// Stiffness painting from the project to the player [A §4.3.5, Fig. 4.10–4.11]: the liver sample
// exported with a painted region on its body (skeleton paint) and on its fascia (polygon paint),
// run headless; the settled shape changes in the direction painted, the fascia's weights travel as
// meshes/fascia.vweights, and a package whose scene names a weights file it lacks is refused.
#include "case/case_package.hpp"
#include "case/zip_craft.hpp"
#include "support/case_signing.hpp"
#include "support/run_process.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <fstream>

using namespace viscera;
using ::testing::HasSubstr;
using vcase::test::ScratchDir;

namespace {

test::ProcessResult run(const char* exe, const std::vector<std::string>& args) {
    return test::runProcess(exe, test::signingWithSampleKey(test::trustingSampleKey(args)));
}

nlohmann::json readJson(const std::filesystem::path& p) {
    std::ifstream in(p);
    return nlohmann::json::parse(in);
}

/// A copy of the liver sample (its texture specs included) under `dir` with `edit` applied to
/// its project.json.
std::filesystem::path projectWith(const std::filesystem::path& dir, const std::string& name,
                                  const std::function<void(nlohmann::json&)>& edit) {
    const auto sample = std::filesystem::path(VISCERA_SOURCE_DIR) / "projects/liver";
    nlohmann::json p = readJson(sample / "project.json");
    edit(p);
    const auto pdir = dir / name;
    std::filesystem::copy(sample, pdir, std::filesystem::copy_options::recursive);
    std::ofstream(pdir / "project.json", std::ios::trunc) << p.dump(1);
    return pdir;
}

/// Exports and runs `frames` frames headless; the largest node displacement from rest at the end, m.
double settledDisplacement(const std::filesystem::path& project, const std::filesystem::path& out, int frames) {
    auto e = run(VISCERA_STUDIO_EXE, {"export", project.string(), "-o", out.string()});
    EXPECT_EQ(e.exitCode, 0) << e.err;
    const auto report = out.parent_path() / (out.stem().string() + ".json");
    auto r = run(VISCERA_PLAYER_EXE,
                 {"run", out.string(), "--headless", "--frames", std::to_string(frames), "--report", report.string()});
    EXPECT_EQ(r.exitCode, 0) << r.err << r.out;
    if (r.exitCode != 0) return NAN;
    const nlohmann::json doc = readJson(report);
    EXPECT_TRUE(doc["invariants"]["all_finite"].get<bool>());
    return doc["metrics"]["final_node_displacement_m"].get<double>();
}

nlohmann::json stroke(double x, double y, double z, double radius, double amplitude, const char* mode) {
    return {{"center", {x, y, z}}, {"radius", radius}, {"amplitude", amplitude}, {"mode", mode}};
}

} // namespace

TEST(PaintedCase, PaintedStiffnessChangesTheSettledLiverInTheDirectionPainted) {
    ScratchDir dir;
    constexpr int kFrames = 150; // 2.5 s: settled (damped) under gravity
    // the free front half of the organ (the back edge y > 4.5 cm is held) painted stiff or soft
    auto painted = [](double amplitude, const char* mode) {
        return [=](nlohmann::json& p) {
            p["bodies"][0]["stiffness_paint"] = {{"base_weight", 1.0},
                                                 {"min_weight", 0.05},
                                                 {"max_weight", 20.0},
                                                 {"strokes", {stroke(0.0, -0.02, 0.0, 0.07, amplitude, mode)}}};
        };
    };
    const double plain = settledDisplacement(projectWith(dir.path(), "plain", [](nlohmann::json&) {}),
                                             dir.path() / "plain.vcase", kFrames);
    const double stiff =
        settledDisplacement(projectWith(dir.path(), "stiff", painted(6.0, "add")), dir.path() / "stiff.vcase", kFrames);
    const double soft = settledDisplacement(projectWith(dir.path(), "soft", painted(0.6, "subtract")),
                                            dir.path() / "soft.vcase", kFrames);
    std::printf("liver max node displacement after %d frames: plain %.2f mm, painted stiff %.2f mm, "
                "painted soft %.2f mm\n",
                kFrames, 1e3 * plain, 1e3 * stiff, 1e3 * soft);
    ASSERT_GT(plain, 0.005) << "the organ sags";
    EXPECT_LT(stiff, 0.95 * plain) << "stiffer where painted: less sag";
    EXPECT_GT(soft, 1.05 * plain) << "softer where painted: more sag";
}

TEST(PaintedCase, FasciaPolygonPaintTravelsAsVweightsAndStiffensTheLayer) {
    ScratchDir dir;
    auto fascia = [](double amplitude) {
        return [=](nlohmann::json& p) {
            p["surfaces"][0]["stiffness_paint"] = {{"base_weight", 1.0},
                                                   {"min_weight", 0.05},
                                                   {"max_weight", 100.0},
                                                   {"strokes", {stroke(0.0, -0.02, 0.04, 0.08, amplitude, "add")}}};
        };
    };
    const auto out = dir.path() / "fascia.vcase";
    const double plain =
        settledDisplacement(projectWith(dir.path(), "plain", [](nlohmann::json&) {}), dir.path() / "plain.vcase", 120);
    const double stiff = settledDisplacement(projectWith(dir.path(), "fascia", fascia(60.0)), out, 120);
    std::printf("liver with its fascia painted up to 61x: max node displacement %.2f mm (unpainted %.2f mm)\n",
                1e3 * stiff, 1e3 * plain);
    EXPECT_LT(stiff, plain) << "a stiffer membrane on the upper face holds the organ up";

    const auto pkg = vcase::CasePackage::open(out);
    ASSERT_TRUE(pkg->contains("meshes/fascia.vweights"));
    const nlohmann::json scene = nlohmann::json::parse(pkg->read("scene.json"));
    EXPECT_EQ(scene["surfaces"][0]["node_weights_file"], "meshes/fascia.vweights");
    // not painted: not packaged
    EXPECT_FALSE(vcase::CasePackage::open(dir.path() / "plain.vcase")->contains("meshes/fascia.vweights"));

    // the same package without the weights file: refused, naming the field and the entry
    std::vector<vcase::test::RawEntry> entries;
    for (const vcase::FileEntry& f : pkg->manifest().files)
        if (f.path != "meshes/fascia.vweights") entries.emplace_back(f.path, std::string(pkg->read(f.path)));
    vcase::Manifest m = pkg->manifest();
    m.files = vcase::test::manifestFor(entries).files;
    const auto broken = dir.path() / "broken.vcase";
    std::ofstream(broken, std::ios::binary) << vcase::test::craftPackage(m, entries);
    auto r = run(VISCERA_PLAYER_EXE, {"run", broken.string(), "--headless", "--frames", "2", "--allow-unsigned"});
    EXPECT_NE(r.exitCode, 0);
    EXPECT_THAT(r.err, HasSubstr("surfaces[0].node_weights_file: 'meshes/fascia.vweights' is not in the package"));
}

// The liver sample's probe is a device tool: the scripted press and the committed palpation
// replay move it onto the organ; the contact force reaches the device, within the case's limit.
TEST(PaintedCase, TheLiverProbeIsDrivenByADevice) {
    ScratchDir dir;
    const auto out = dir.path() / "liver.vcase";
    auto e = run(VISCERA_STUDIO_EXE, {"export", (std::filesystem::path(VISCERA_SOURCE_DIR) / "projects/liver").string(),
                                      "-o", out.string()});
    ASSERT_EQ(e.exitCode, 0) << e.err;
    EXPECT_THAT(e.out, ::testing::HasSubstr("probe"));
    const std::string replay =
        "replay:" + (std::filesystem::path(VISCERA_SOURCE_DIR) / "projects/liver/replays/palpation.csv").string();
    for (const std::string& device : {std::string("scripted:press"), replay}) {
        const auto report = dir.path() / "r.json";
        auto r = run(VISCERA_PLAYER_EXE, {"run", out.string(), "--headless", "--frames", "200", "--device", device,
                                          "--report", report.string()});
        ASSERT_EQ(r.exitCode, 0) << device << ": " << r.err << r.out;
        const nlohmann::json doc = readJson(report);
        EXPECT_TRUE(doc["invariants"]["all_finite"].get<bool>()) << device;
        EXPECT_TRUE(doc["warnings"].empty()) << device << ": " << doc["warnings"].dump();
        EXPECT_EQ(doc["metrics"]["tool_names"], nlohmann::json({"probe"}));
        EXPECT_GT(doc["metrics"]["tool_path_length_m"].get<double>(), 0.02) << device;
        EXPECT_GT(doc["metrics"]["device_max_force_n"].get<double>(), 0.1) << device << ": the probe pressed the organ";
        EXPECT_LE(doc["metrics"]["device_max_force_n"].get<double>(),
                  doc["haptics"]["case_max_force_n"].get<double>() + 1e-9);
        // The probe through its laparoscopic port in every frame.
        ASSERT_EQ(doc["ports"].size(), 1u) << device;
        const nlohmann::json& port = doc["ports"][0];
        EXPECT_EQ(port["mode"], "laparoscopic");
        EXPECT_EQ(port["frames"].get<int>(), 200);
        EXPECT_FALSE(port.contains("max_shaft_distance_m")) << "a probe's shaft is drawn through its port";
        EXPECT_GE(port["insertion_used_m"][0].get<double>(), port["insertion_limits_m"][0].get<double>() - 1e-9);
        EXPECT_LE(port["insertion_used_m"][1].get<double>(), port["insertion_limits_m"][1].get<double>() + 1e-9);
        EXPECT_GT(port["insertion_used_m"][1].get<double>(), port["insertion_used_m"][0].get<double>() + 0.01)
            << device << ": the probe went in through the port";
    }
}
