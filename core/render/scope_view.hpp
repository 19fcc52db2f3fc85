#pragma once
/// The view through the laparoscope (sim/scene/laparoscope.hpp): the camera at the optic's tip
/// looking along its viewing direction, and the head light — the renderer's area light — at the
/// tip, facing the same way, sized as a scope's light ring and bright enough for its working
/// distance.
#include "render/settings.hpp"
#include "render/tool_meshes.hpp"

namespace viscera::render {

/// m: the distance at which the head light's irradiance is about 0.9 (what defaultSettingsFor
/// gives its target), the tissue a laparoscope works on.
inline constexpr float kScopeWorkingDistance = 0.08f;

/// Sets `settings`' camera, light and light sampling bands from `scope` (nothing when it is not
/// present or not finite).
void viewThroughScope(RenderSettings& settings, const ToolPoses::Scope& scope);

} // namespace viscera::render
