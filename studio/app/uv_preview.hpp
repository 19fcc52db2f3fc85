#pragma once
/// The checker preview of a UV transfer [issue 16 item 2]: surfaces side by side, each textured
/// with a checker whose tint runs with u (red) and v (green), rendered headless (EGL) to a PNG.
/// A transfer that keeps the source's parameterization shows the same even checks as the source;
/// a triangle over a seam shows the whole atlas squeezed into it (a smear of tints).
#include "bake/remesh.hpp"
#include "bake/uv_transfer.hpp"
#include "render/image.hpp"

#include <filesystem>
#include <string>
#include <vector>

namespace viscera::studio {

struct UvPreviewItem {
    std::string name;
    sim::TriMesh mesh;
    std::vector<bake::CornerUv> uv; ///< one per triangle
    /// Empty, or #V × 4 (RGBA in [0, 1], one per vertex of `mesh`): drawn over the checker by its
    /// alpha (the stretch heat map and the seams).
    std::vector<float> overlay;
};

/// The stretch heat map of a transfer with its seams: per vertex of `mesh`, the largest stretch
/// of its triangles (UvTransferStats::faceStretch: 1 = none, ≥ kUvStretchThreshold = red,
/// infinite = flipped, magenta) as an RGBA overlay; vertices of `seamEdges` dark.
std::vector<float> stretchOverlay(const sim::TriMesh& mesh, const std::vector<double>& faceStretch,
                                  const std::vector<std::array<int32_t, 2>>& seamEdges);

/// The checker texture: `size` × `size`, `checks` checks per side.
render::Image uvCheckerImage(int size = 512, int checks = 16);

/// Renders the items left to right (each shifted by 1.25 × the widest item's x extent) and writes
/// the PNG. Throws std::runtime_error naming the cause when no OpenGL context can be made or the
/// PNG cannot be written.
void writeUvPreview(const std::filesystem::path& png, const std::vector<UvPreviewItem>& items, int width = 1800,
                    int height = 700);

} // namespace viscera::studio
