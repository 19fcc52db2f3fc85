#pragma once
/// The hepatocystic anatomy [issue 57 item 4] written as a medical artist receives bought
/// anatomy: one OBJ file with UVs per part (bake::hepatocysticAnatomy: liver, gallbladder,
/// cystic duct, common bile duct, cystic artery) and the texture atlas they share, as a PNG.
/// No project: the artist builds the case from these files in the studio (Import anatomy, Make
/// simulation-ready, Tetrahedralize, then ports, instruments, scope, task and assessment).
#include <filesystem>
#include <vector>

namespace viscera::studio {

struct HepatocysticFiles {
    std::vector<std::filesystem::path> parts; ///< <dir>/<part>.obj, in bake::hepatocysticAnatomy's order
    std::filesystem::path atlas;              ///< <dir>/hepatocystic.png
};

/// Writes the parts and the atlas into `dir` (made when missing; each file written atomically).
/// Throws viscera::InputError naming the path when `dir` cannot be written.
HepatocysticFiles writeHepatocysticAnatomy(const std::filesystem::path& dir);

} // namespace viscera::studio
