#pragma once
/// The "render" block of a case's scene (scene.json / project.json): what the case's look uses, so
/// that nothing runs that the case does not need — a switched-off post effect or SSS runs no pass.
///
///   "render": {
///     "sss": true,                                  subsurface scattering [A eq. 6.8–6.10]
///     "sampling": "distance",                       uniform | distance | painted [A eq. 6.15–6.16]
///     "stereo": "off",                              off | side_by_side | anaglyph [B ch. 4]
///     "post": {"tone_mapping": true, "colour_curve": false, "chromatic_aberration": false,
///              "depth_of_field": false, "noise": false, "sharpen": false, "radial_mask": false},
///     "materials": {                                material maps per body or surface [A §6.2.2]
///       "organ": {"diffuse": "textures/organ_diffuse.png", "roughness": "textures/organ_roughness.png",
///                 "metallic": "...", "normal": "...",   package entries (PNG); at least one map
///                 "tiles_per_metre": 20,               triplanar repeats per metre, (0, 10000]
///                 "normal_strength": 1,                [0, 4]
///                 "uv": "meshes/organ.vuv"}            a body's UVs per boundary corner
///                                                      (render/corner_uv.hpp): the maps are laid
///                                                      by them instead of triplanar
///     }
///   }
///
/// Every key is optional; a post effect not named keeps the renderer's default (off, except
/// tone mapping). Parsing is strict: unknown keys and wrong types are errors.
#include "render/material.hpp"
#include "render/settings.hpp"

#include <functional>
#include <memory>

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace viscera::sim {
class JsonField;
}

namespace viscera::render {

/// Applies `json` (the text of the "render" object; empty: nothing to apply) to `settings`.
/// Throws viscera::InputError "<origin>: render.<field>: <rule>" on malformed input; `settings`
/// is then unchanged.
void applyCaseRender(RenderSettings& settings, std::string_view json, const std::string& origin);

/// One entry of "render.materials": the maps body or surface `target` is drawn with.
struct CaseMaterialMaps {
    std::string target;
    std::string diffuse, roughness, metallic, normal; ///< package entries; empty: that map is not used
    float tilesPerMetre = 20.0f;
    float normalStrength = 1.0f;
    std::string uv; ///< package entry of the body's corner UVs (render/corner_uv.hpp), or empty
    /// The map entries named, in the order diffuse, roughness, metallic, normal (not `uv`).
    std::vector<std::string> files() const;
};

/// The "materials" of the "render" object `json` (empty text or no "materials": none), sorted
/// by name (deterministic). Throws viscera::InputError "<origin>: render.materials.<name>.<field>:
/// <rule>" (unknown field, bad entry name, no map, number out of range). Whether each target is
/// a body or surface of the scene is the caller's check (it knows the scene).
std::vector<CaseMaterialMaps> caseMaterialMaps(std::string_view json, const std::string& origin);

/// The optional "tiles_per_metre" (0, 10000] and "normal_strength" [0, 4] of object `j` (a
/// render.materials entry or a project's texture block: one rule for both).
void readMapLayout(const sim::JsonField& j, float& tilesPerMetre, float& normalStrength);

/// Decodes the maps of `entry`: `read(path)` gives an entry's bytes (the case package's), each a
/// PNG of at most 4096 pixels a side, all of one size. Throws viscera::InputError naming `origin`,
/// the entry and the rule.
std::shared_ptr<const MaterialMaps> loadMaterialMaps(const CaseMaterialMaps& entry,
                                                     const std::function<std::string_view(const std::string&)>& read,
                                                     const std::string& origin);

/// Bytes the decoded maps of a case may take together (8-bit RGBA): 128 MiB, two 4096² maps or
/// every map of four tissues at 2048².
inline constexpr uint64_t kMaxDecodedImageBytes = uint64_t(128) << 20;
/// Refuses, before any map is decoded, maps of `entries` that would decode to more than `budget`
/// bytes together (their sizes read from the PNG headers). Throws viscera::InputError
/// "<origin>: render.materials: the maps decode to 192 MiB (3 maps), more than the 128 MiB budget
/// of a case's images".
void checkDecodedImageBudget(const std::vector<CaseMaterialMaps>& entries,
                             const std::function<std::string_view(const std::string&)>& read, const std::string& origin,
                             uint64_t budget = kMaxDecodedImageBytes);

class SceneView;
/// Draws every mesh of `view` named `target` with a copy of its material that carries `maps`.
/// Returns the number of meshes changed.
size_t applyMaterialMaps(SceneView& view, const std::string& target, std::shared_ptr<const MaterialMaps> maps);

} // namespace viscera::render
