#pragma once
/// The checker preview of a UV transfer [issue 16 item 2]: surfaces side by side, each textured
/// with a checker whose tint runs with u (red) and v (green), rendered headless (EGL) to a PNG.
/// A transfer that keeps the source's parameterization shows the same even checks as the source;
/// a triangle over a seam shows the whole atlas squeezed into it (a smear of tints).
#include "bake/remesh.hpp"
#include "render/image.hpp"

#include <filesystem>
#include <string>
#include <vector>

namespace viscera::studio {

struct UvPreviewItem {
    std::string name;
    sim::TriMesh mesh;
    std::vector<bake::CornerUv> uv; ///< one per triangle
};

/// The checker texture: `size` × `size`, `checks` checks per side.
render::Image uvCheckerImage(int size = 512, int checks = 16);

/// Renders the items left to right (each shifted by 1.25 × the widest item's x extent) and writes
/// the PNG. Throws std::runtime_error naming the cause when no OpenGL context can be made or the
/// PNG cannot be written.
void writeUvPreview(const std::filesystem::path& png, const std::vector<UvPreviewItem>& items, int width = 1800,
                    int height = 700);

} // namespace viscera::studio
