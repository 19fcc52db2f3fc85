#include "render/case_settings.hpp"

#include "sim/util/error.hpp"

#include <nlohmann/json.hpp>

#include <map>

namespace viscera::render {

void applyCaseRender(RenderSettings& settings, std::string_view text, const std::string& origin) {
    if (text.empty()) return;
    using nlohmann::json;
    auto fail = [&](const std::string& field, const std::string& rule) {
        throw InputError(origin + ": render" + (field.empty() ? "" : "." + field) + ": " + rule);
    };
    const json doc = json::parse(text, nullptr, false);
    if (doc.is_discarded() || !doc.is_object()) fail("", "must be a JSON object");
    RenderSettings s = settings;
    auto boolean = [&](const json& v, const std::string& field) {
        if (!v.is_boolean()) fail(field, "must be true or false");
        return v.get<bool>();
    };
    auto choice = [&](const json& v, const std::string& field, const std::map<std::string, int>& options) {
        std::string list;
        for (const auto& [name, _] : options) list += (list.empty() ? "" : ", ") + name;
        if (!v.is_string()) fail(field, "must be one of " + list);
        const auto it = options.find(v.get<std::string>());
        if (it == options.end()) fail(field, "'" + v.get<std::string>() + "' is not one of " + list);
        return it->second;
    };
    for (const auto& [key, v] : doc.items()) {
        if (key == "sss") {
            s.subsurface = boolean(v, key);
        } else if (key == "sampling") {
            s.sampling.mode = static_cast<SampleMode>(choice(
                v, key,
                {{"uniform", int(SampleMode::Uniform)}, {"distance", int(SampleMode::Distance)},
                 {"painted", int(SampleMode::Painted)}}));
        } else if (key == "stereo") {
            s.stereo.mode = static_cast<StereoMode>(choice(
                v, key,
                {{"off", int(StereoMode::Off)}, {"side_by_side", int(StereoMode::SideBySide)},
                 {"anaglyph", int(StereoMode::Anaglyph)}}));
        } else if (key == "post") {
            if (!v.is_object()) fail(key, "must be an object");
            const std::map<std::string, bool*> effects = {
                {"depth_of_field", &s.post.depthOfField.enabled},
                {"chromatic_aberration", &s.post.chromaticAberration.enabled},
                {"tone_mapping", &s.post.toneMapping.enabled},
                {"colour_curve", &s.post.colourCurve.enabled},
                {"sharpen", &s.post.sharpen.enabled},
                {"noise", &s.post.noise.enabled},
                {"radial_mask", &s.post.radialMask.enabled}};
            for (const auto& [name, on] : v.items()) {
                const auto it = effects.find(name);
                if (it == effects.end())
                    fail("post." + name,
                         "unknown effect (known: chromatic_aberration, colour_curve, depth_of_field, "
                         "noise, radial_mask, sharpen, tone_mapping)");
                *it->second = boolean(on, "post." + name);
            }
        } else {
            fail(key, "unknown field (known: post, sampling, sss, stereo)");
        }
    }
    settings = std::move(s);
}

} // namespace viscera::render
