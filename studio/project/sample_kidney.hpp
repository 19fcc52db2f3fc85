#pragma once
/// The kidney sample project [issue 38 item 4], made by code: the kidney-like render anatomy
/// (bake::kidneyAnatomy: four overlapping parts, a self-intersection, a hole, UV islands and
/// seams) written as OBJ files with UVs, its texture atlas as a PNG, and a project.json whose
/// body is made from them by the remesh block (remesh, seam-cutting UV transfer, tetrahedralize).
#include "project/project.hpp"

#include <filesystem>

namespace viscera::studio {

/// Writes anatomy/{cortex,pelvis,ureter,artery}.obj, anatomy/kidney.png and project.json into
/// `dir` (made when missing; files written atomically) and returns the project as loaded from
/// it. Throws viscera::InputError naming the path when `dir` cannot be written.
Project writeKidneySample(const std::filesystem::path& dir);

} // namespace viscera::studio
