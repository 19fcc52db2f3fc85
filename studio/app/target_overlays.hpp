#pragma once
/// What the assessment's target tool draws (studio viewport, authoring only) [issue 57 item 2]:
/// the task's targets on the anatomy while the Assessment dock is open. Each kind is one thin-tube
/// mesh in its own colour (an empty mesh when there is none of that kind).
#include "render/scene_view.hpp"
#include "sim/scene/assessment.hpp"

#include <optional>
#include <vector>

namespace viscera::studio {

/// The cut lines as orange tubes (radius 0.7 mm, drawn on top of the surface they lie on) with a ring of the target's
/// radius about the line at each end and at each interior point 1 cm on from the last ring (the band a cut counts in).
/// Named "cut targets"; empty mesh for no line.
render::RenderMesh cutTargetsMesh(const std::vector<sim::CutTarget>& cuts, uint32_t material);

/// Each clip site as a yellow three-axis cross (half size 2 mm) inside three rings of the
/// target's tolerance (the sphere a clip counts in). Named "clip targets".
render::RenderMesh clipTargetsMesh(const std::vector<sim::ClipTarget>& clips, uint32_t material);

/// The suture plane as a magenta square of side `size` (m) about its point, with its normal
/// drawn as a line of half that length and a ring at each end of the bite spacing's maximum.
/// Named "suture target".
render::RenderMesh sutureTargetMesh(const sim::SutureTarget& suture, double size, uint32_t material);

/// What is being picked and not yet taken: a cut line's stroke so far (white tubes) and the first
/// point of a suture plane (a white cross). Named "target stroke"; empty mesh for nothing.
render::RenderMesh pendingTargetMesh(const std::vector<sim::Vec3>& stroke, const std::optional<sim::Vec3>& point,
                                     uint32_t material);

} // namespace viscera::studio
