// viscera-render-snapshot: renders a case (or a generated organ) headless and writes a PNG, with
// the frame time of every pass. A developer tool for looking at the renderer's output.
//
//   viscera-render-snapshot <case.vcase> [--frames N] [-o out.png] [--size WxH]
//                           [--post none|all|<effect>,...] [--stereo sbs|anaglyph]
//                           [--samples uniform1|distance|reference] [--heat]
//   viscera-render-snapshot --liver [...]   a generated liver-like surface, no simulation
#include "render/headless.hpp"
#include "runtime/session.hpp"
#include "sim/mesh/generators.hpp"
#include "sim/util/error.hpp"

#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>

using namespace viscera;

namespace {

int usage() {
    std::fputs("usage: viscera-render-snapshot (<case.vcase> | --liver) [--frames N] [-o out.png] [--size WxH]\n"
               "         [--post none|all|dof,chromatic,tonemap,curve,sharpen,noise,mask] [--stereo sbs|anaglyph]\n"
               "         [--samples uniform1|distance|reference] [--heat]\n",
               stderr);
    return 2;
}

void enablePost(render::PostSettings& p, const std::string& list) {
    if (list == "none") return p.disableAll();
    std::stringstream ss(list);
    std::string e;
    while (std::getline(ss, e, ',')) {
        const bool all = e == "all";
        if (all || e == "dof") p.depthOfField.enabled = true;
        if (all || e == "chromatic") p.chromaticAberration.enabled = true;
        if (all || e == "tonemap") p.toneMapping.enabled = true;
        if (all || e == "curve") p.colourCurve.enabled = true;
        if (all || e == "sharpen") p.sharpen.enabled = true;
        if (all || e == "noise") p.noise.enabled = true;
        if (all || e == "mask") p.radialMask.enabled = true;
    }
}

} // namespace

int main(int argc, char** argv) {
    std::string input, out = "snapshot.png", post = "tonemap", stereo, samples = "distance";
    int frames = 1, width = 640, height = 480;
    bool liver = false, heat = false;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        auto next = [&]() -> std::string { return i + 1 < argc ? argv[++i] : ""; };
        if (a == "--frames")
            frames = std::max(0, std::atoi(next().c_str()));
        else if (a == "-o")
            out = next();
        else if (a == "--size") {
            const std::string v = next();
            if (std::sscanf(v.c_str(), "%dx%d", &width, &height) != 2) return usage();
        } else if (a == "--post")
            post = next();
        else if (a == "--stereo")
            stereo = next();
        else if (a == "--samples")
            samples = next();
        else if (a == "--liver")
            liver = true;
        else if (a == "--heat")
            heat = true;
        else if (!a.empty() && a[0] == '-')
            return usage();
        else
            input = a;
    }
    if (input.empty() && !liver) return usage();
    try {
        render::SceneView view;
        player::LoadedCase loaded;
        if (liver) {
            const uint32_t mat = view.addMaterial(render::defaultMaterialFor("liver"));
            view.addMesh("liver", sim::makeLiverSurface(sim::Vec3::Zero(), sim::Vec3(0.1, 0.07, 0.04), 0.5, 96, 48),
                         mat);
        } else {
            vcase::TrustPolicy any; // a developer's tool: it renders the case it is given, signed or not
            any.allowUnsigned = true;
            loaded = player::loadCase(input, any);
            for (int f = 0; f < frames; ++f)
                loaded.world->step();
            view = player::caseView(loaded);
        }
        if (heat && !view.meshes().empty()) {
            // A dissection line across the first mesh: heat falls off with distance from the x = 0 plane.
            render::RenderMesh& m = view.meshes()[0];
            std::vector<float> h(m.vertexCount());
            for (size_t v = 0; v < h.size(); ++v)
                h[v] = std::max(0.0f, 1.0f - std::abs(m.positions[3 * v]) / 0.012f);
            view.setHeat(0, h);
        }
        render::RenderSettings s = render::defaultSettingsFor(view, width, height);
        s.post.disableAll();
        enablePost(s.post, post);
        if (stereo == "sbs")
            s.stereo.mode = render::StereoMode::SideBySide;
        else if (stereo == "anaglyph")
            s.stereo.mode = render::StereoMode::Anaglyph;
        if (samples == "uniform1")
            s.sampling.mode = render::SampleMode::Uniform;
        else if (samples == "reference")
            s.sampling.mode = render::SampleMode::Reference;
        std::string why;
        auto r = render::HeadlessRenderer::create(s, &why);
        if (!r) {
            std::fprintf(stderr, "viscera-render-snapshot: no OpenGL context: %s\n", why.c_str());
            return 1;
        }
        r->renderFrame(view); // warm-up (shader compilation, first upload)
        const render::FrameStats& st = r->renderFrame(view);
        r->writePng(out);
        std::printf("%s: %dx%d, %zu meshes, device %s\n", out.c_str(), width, height, view.meshes().size(),
                    r->description().c_str());
        for (const auto& p : st.passes)
            std::printf("  %-22s eye %d  %8.2f ms\n", p.name.c_str(), p.eye, p.ms);
        std::printf("  %-22s        %8.2f ms\n  %-22s        %8.2f ms\n", "upload", st.uploadMs, "frame", st.totalMs);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "viscera-render-snapshot: %s\n", e.what());
        return 1;
    }
    return 0;
}
