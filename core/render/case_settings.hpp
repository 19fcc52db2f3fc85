#pragma once
/// The "render" block of a case's scene (scene.json / project.json): what the case's look uses, so
/// that nothing runs that the case does not need — a switched-off post effect or SSS runs no pass.
///
///   "render": {
///     "sss": true,                                  subsurface scattering [A eq. 6.8–6.10]
///     "sampling": "distance",                       uniform | distance | painted [A eq. 6.15–6.16]
///     "stereo": "off",                              off | side_by_side | anaglyph [B ch. 4]
///     "post": {"tone_mapping": true, "colour_curve": false, "chromatic_aberration": false,
///              "depth_of_field": false, "noise": false, "sharpen": false, "radial_mask": false}
///   }
///
/// Every key is optional; a post effect not named keeps the renderer's default (off, except
/// tone mapping). Parsing is strict: unknown keys and wrong types are errors.
#include "render/settings.hpp"

#include <string>
#include <string_view>

namespace viscera::render {

/// Applies `json` (the text of the "render" object; empty: nothing to apply) to `settings`.
/// Throws viscera::InputError "<origin>: render.<field>: <rule>" on malformed input; `settings`
/// is then unchanged.
void applyCaseRender(RenderSettings& settings, std::string_view json, const std::string& origin);

} // namespace viscera::render
