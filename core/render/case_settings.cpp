#include "render/case_settings.hpp"

#include "sim/util/error.hpp"
#include "sim/util/json_reader.hpp"

namespace viscera::render {

void applyCaseRender(RenderSettings& settings, std::string_view text, const std::string& origin) {
    if (text.empty()) return;
    const nlohmann::json doc = sim::parseJsonText(text, origin);
    const sim::JsonField root(doc, "render", origin);
    root.object({"sss", "sampling", "stereo", "post"});
    RenderSettings s = settings;
    s.subsurface = root.boolean("sss", s.subsurface);
    if (auto v = root.find("sampling")) {
        const std::string m = v->choice({"uniform", "distance", "painted"}, "a sampling mode");
        s.sampling.mode = m == "uniform"    ? SampleMode::Uniform
                          : m == "distance" ? SampleMode::Distance
                                            : SampleMode::Painted;
    }
    if (auto v = root.find("stereo")) {
        const std::string m = v->choice({"off", "side_by_side", "anaglyph"}, "a stereo mode");
        s.stereo.mode = m == "off"            ? StereoMode::Off
                        : m == "side_by_side" ? StereoMode::SideBySide
                                              : StereoMode::Anaglyph;
    }
    if (auto post = root.find("post")) {
        post->object({"chromatic_aberration", "colour_curve", "depth_of_field", "noise", "radial_mask", "sharpen",
                      "tone_mapping"});
        const std::pair<const char*, bool*> effects[] = {{"depth_of_field", &s.post.depthOfField.enabled},
                                                         {"chromatic_aberration", &s.post.chromaticAberration.enabled},
                                                         {"tone_mapping", &s.post.toneMapping.enabled},
                                                         {"colour_curve", &s.post.colourCurve.enabled},
                                                         {"sharpen", &s.post.sharpen.enabled},
                                                         {"noise", &s.post.noise.enabled},
                                                         {"radial_mask", &s.post.radialMask.enabled}};
        for (const auto& [name, on] : effects)
            *on = post->boolean(name, *on);
    }
    settings = std::move(s);
}

} // namespace viscera::render
