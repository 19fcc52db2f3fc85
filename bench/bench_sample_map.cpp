// Painted light sampling through the whole path (issue: studio painting): a studio project with
// light_samples (default: the liver sample) is exported to a case, the case is loaded as the player
// loads it (player::loadCase, its .vsamples maps on the bodies and on the fascia over them) and
// rendered headless at the player's default view, uniform 1× and painted against the many-sample
// reference (render::compareSampling: RMSE near the light, frame time in the same run).
//   bench_sample_map [out-dir] [project-dir] [--frames N] [--size WxH]
// Writes <out>/case.vcase, sample_reference.png, sample_uniform1.png, sample_painted.png,
// sample_compare.json, and prints the table.
#include "project/project.hpp"
#include "render/case_settings.hpp"
#include "render/sample_map.hpp"
#include "render/sampling_compare.hpp"
#include "runtime/session.hpp"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

using namespace viscera;

int main(int argc, char** argv) {
    std::filesystem::path out = "bench-out/sample-map";
    std::filesystem::path projectDir = std::string(VISCERA_SOURCE_DIR) + "/projects/liver";
    int frames = 15, w = 640, h = 480, positional = 0;
    for (int i = 1; i < argc; ++i) {
        if (!std::strcmp(argv[i], "--frames") && i + 1 < argc)
            frames = std::max(1, std::atoi(argv[++i]));
        else if (!std::strcmp(argv[i], "--size") && i + 1 < argc)
            std::sscanf(argv[++i], "%dx%d", &w, &h);
        else if (positional++ == 0)
            out = argv[i];
        else
            projectDir = argv[i];
    }
    try {
        std::filesystem::create_directories(out);
        const studio::Project project = studio::loadProject(projectDir);
        if (!studio::usesPaintedSampling(project.scene))
            throw std::runtime_error(projectDir.string() + "/project.json: render.sampling is not 'painted'");
        const std::filesystem::path casePath = out / "case.vcase";
        studio::exportCase(project, casePath);
        vcase::TrustPolicy any; // the benchmark's own unsigned case
        any.allowUnsigned = true;
        player::LoadedCase loaded = player::loadCase(casePath, any);
        const render::SceneView view = player::caseView(loaded);
        render::RenderSettings base = render::defaultSettingsFor(view, w, h);
        render::applyCaseRender(base, loaded.scene.render, casePath.string());
        std::string why;
        auto r = render::HeadlessRenderer::create(base, &why);
        if (!r) throw std::runtime_error("no OpenGL context: " + why);
        r->renderFrame(view); // shader compilation and first upload
        const auto cmp = render::compareSampling(*r, view, base, frames);
        render::writePng(out / "sample_reference.png", cmp->reference);
        render::writePng(out / "sample_uniform1.png", cmp->uniform);
        render::writePng(out / "sample_painted.png", cmp->painted);
        nlohmann::json j;
        j["case"] = casePath.string();
        j["device"] = r->description();
        j["size"] = {w, h};
        j["near_distance_m"] = cmp->nearDistance;
        j["near_pixels"] = cmp->nearPixels;
        j["drawn_pixels"] = cmp->drawnPixels;
        j["rmse_near"] = {{"uniform1", cmp->rmseNearUniform}, {"painted", cmp->rmseNearPainted}};
        j["rmse_all"] = {{"uniform1", cmp->rmseUniform}, {"painted", cmp->rmsePainted}};
        j["frame_ms"] = {{"uniform1", cmp->msUniform}, {"painted", cmp->msPainted}};
        j["frame_ratio"] = cmp->msPainted / cmp->msUniform;
        nlohmann::json bodies = nlohmann::json::array();
        for (size_t b = 0; b < view.meshes().size(); ++b) {
            const auto a = render::sampleClassAreas(view.meshes()[b]);
            const double all = a[0] + a[1] + a[2] + a[3];
            bodies.push_back(
                {{"mesh", view.meshes()[b].name},
                 {"area_share",
                  {{"unpainted", a[0] / all}, {"1x", a[1] / all}, {"4x", a[2] / all}, {"8x", a[3] / all}}}});
        }
        j["meshes"] = bodies;
        std::ofstream(out / "sample_compare.json") << j.dump(2) << "\n";
        std::printf("bench_sample_map: %s, %dx%d, %s\n", casePath.c_str(), w, h, r->description().c_str());
        std::printf("near the light: %zu of %zu drawn px (surface within %.3f m of the light)\n", cmp->nearPixels,
                    cmp->drawnPixels, cmp->nearDistance);
        std::printf("%-10s %12s %12s %10s %8s\n", "mode", "RMSE near", "RMSE all", "frame ms", "vs 1x");
        std::printf("%-10s %12.3f %12.3f %10.2f %8.3f\n", "uniform1", cmp->rmseNearUniform, cmp->rmseUniform,
                    cmp->msUniform, 1.0);
        std::printf("%-10s %12.3f %12.3f %10.2f %8.3f\n", "painted", cmp->rmseNearPainted, cmp->rmsePainted,
                    cmp->msPainted, cmp->msPainted / cmp->msUniform);
        for (const auto& m : bodies)
            std::printf("  %s: area share %s\n", m["mesh"].get<std::string>().c_str(), m["area_share"].dump().c_str());
        return 0;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bench_sample_map: %s\n", e.what());
        return 1;
    }
}
