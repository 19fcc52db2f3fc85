#pragma once
/// Anatomy made by code written as a medical artist receives bought anatomy: one OBJ file with
/// UVs per part and, where the parts share one, their texture atlas as a PNG. No project: the
/// artist builds the case from these files in the studio (Import anatomy, Make simulation-ready,
/// Tetrahedralize, then ports, instruments, scope, task and assessment).
#include <filesystem>
#include <vector>

namespace viscera::studio {

struct AnatomyFiles {
    std::vector<std::filesystem::path> parts; ///< <dir>/<part>.obj, in the generator's order
    std::filesystem::path atlas;              ///< <dir>/<name>.png; empty when none is written
};

/// The hepatocystic triangle [issue 57 item 4] (bake::hepatocysticAnatomy: liver, gallbladder,
/// cystic duct, common bile duct, cystic artery) and the atlas they share, hepatocystic.png.
/// Writes into `dir` (made when missing; each file written atomically). Throws
/// viscera::InputError naming the path when `dir` cannot be written.
AnatomyFiles writeHepatocysticAnatomy(const std::filesystem::path& dir);

/// The mesorectum and its pelvis [issue 57 item 5] (bake::rectumAnatomy: mesorectum, rectum,
/// pelvic_wall, peritoneum); no atlas (the rectum project lays procedural textures by their UVs).
/// Same rules as writeHepatocysticAnatomy.
AnatomyFiles writeRectumAnatomy(const std::filesystem::path& dir);

} // namespace viscera::studio
