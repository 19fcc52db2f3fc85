#include "render/case_settings.hpp"

#include "render/scene_view.hpp"

#include "sim/util/error.hpp"
#include "sim/util/json_reader.hpp"

#include <optional>

namespace viscera::render {

namespace {

std::vector<CaseMaterialMaps> readMaterials(const sim::JsonField& root) {
    std::vector<CaseMaterialMaps> out;
    auto materials = root.find("materials");
    if (!materials) return out;
    for (const auto& [name, m] : materials->anyObject().members()) {
        m.object({"diffuse", "roughness", "metallic", "normal", "tiles_per_metre", "normal_strength", "uv"});
        CaseMaterialMaps c;
        c.target = name;
        const std::pair<const char*, std::string*> maps[] = {
            {"diffuse", &c.diffuse}, {"roughness", &c.roughness}, {"metallic", &c.metallic}, {"normal", &c.normal}};
        for (const auto& [key, path] : maps)
            if (auto f = m.find(key)) *path = f->entryPath();
        if (c.files().empty()) m.fail("names no map (give at least one of diffuse, roughness, metallic, normal)");
        if (auto f = m.find("uv")) c.uv = f->entryPath();
        readMapLayout(m, c.tilesPerMetre, c.normalStrength);
        out.push_back(std::move(c));
    }
    return out;
}

} // namespace

void readMapLayout(const sim::JsonField& j, float& tilesPerMetre, float& normalStrength) {
    tilesPerMetre = float(j.number("tiles_per_metre", tilesPerMetre, sim::NumberRule::aboveUpTo(0, 1e4)));
    normalStrength = float(j.number("normal_strength", normalStrength, sim::NumberRule::closed(0, 4)));
}

std::vector<std::string> CaseMaterialMaps::files() const {
    std::vector<std::string> f;
    for (const std::string* p : {&diffuse, &roughness, &metallic, &normal})
        if (!p->empty()) f.push_back(*p);
    return f;
}

std::vector<CaseMaterialMaps> caseMaterialMaps(std::string_view text, const std::string& origin) {
    if (text.empty()) return {};
    const nlohmann::json doc = sim::parseJsonText(text, origin);
    return readMaterials(sim::JsonField(doc, "render", origin).anyObject());
}

std::shared_ptr<const MaterialMaps> loadMaterialMaps(const CaseMaterialMaps& entry,
                                                     const std::function<std::string_view(const std::string&)>& read,
                                                     const std::string& origin) {
    auto maps = std::make_shared<MaterialMaps>();
    maps->tilesPerMetre = entry.tilesPerMetre;
    maps->normalStrength = entry.normalStrength;
    const std::pair<const std::string*, Image*> slots[] = {{&entry.diffuse, &maps->diffuse},
                                                           {&entry.roughness, &maps->roughness},
                                                           {&entry.metallic, &maps->metallic},
                                                           {&entry.normal, &maps->normal}};
    const Image* first = nullptr;
    const std::string* firstPath = nullptr;
    for (const auto& [path, image] : slots) {
        if (path->empty()) continue;
        *image = decodePng(read(*path), origin + ":" + *path, 4096);
        if (first && (image->width != first->width || image->height != first->height))
            throw InputError(origin + ": render.materials." + entry.target + ": '" + *path + "' is " +
                             std::to_string(image->width) + " x " + std::to_string(image->height) + ", '" + *firstPath +
                             "' is " + std::to_string(first->width) + " x " + std::to_string(first->height) +
                             " (a material's maps must have one size)");
        if (!first) {
            first = image;
            firstPath = path;
        }
    }
    return maps;
}

void checkDecodedImageBudget(const std::vector<CaseMaterialMaps>& entries,
                             const std::function<std::string_view(const std::string&)>& read, const std::string& origin,
                             uint64_t budget) {
    uint64_t total = 0;
    size_t maps = 0;
    for (const CaseMaterialMaps& e : entries)
        for (const std::string& f : e.files()) {
            const auto [w, h] = pngSize(read(f), origin + ":" + f);
            total += uint64_t(w) * h * 4;
            ++maps;
        }
    if (total <= budget) return;
    auto mib = [](uint64_t b) { return std::to_string((b + (1u << 20) - 1) >> 20); };
    throw InputError(origin + ": render.materials: the maps decode to " + mib(total) + " MiB (" + std::to_string(maps) +
                     " maps), more than the " + mib(budget) + " MiB budget of a case's images");
}

size_t applyMaterialMaps(SceneView& view, const std::string& target, std::shared_ptr<const MaterialMaps> maps) {
    size_t changed = 0;
    std::optional<uint32_t> material; // one new material for all of the target's meshes
    for (RenderMesh& m : view.meshes()) {
        if (m.name != target && !(m.cutSurface && m.name == target + " cut surface")) continue;
        if (!material) {
            TissueMaterial mat = view.materials().at(m.material);
            mat.maps = maps;
            material = view.addMaterial(mat);
        }
        m.material = *material;
        ++changed;
    }
    return changed;
}

void applyCaseRender(RenderSettings& settings, std::string_view text, const std::string& origin) {
    if (text.empty()) return;
    const nlohmann::json doc = sim::parseJsonText(text, origin);
    const sim::JsonField root(doc, "render", origin);
    root.object({"sss", "sampling", "stereo", "post", "materials"});
    readMaterials(root); // checked with the rest of the block (the maps are read by the loader)
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
