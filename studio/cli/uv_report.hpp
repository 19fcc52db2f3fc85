#pragma once
/// `viscera-studio remesh` with UVs: the three transfers measured on the kidney (or imported)
/// parts, one `name value` line per figure, the chosen method's surface and UVs for the OBJ, and
/// the checker preview [issue 38 item 1].
#include "bake/remesh.hpp"
#include "bake/uv_transfer.hpp"

#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

/// "seam-cut", "closest", "island": the method names of --uv-transfer. Throws
/// std::invalid_argument naming the option and the three names for anything else.
viscera::bake::UvTransferMethod parseUvTransferOption(std::string_view name);

/// The short name of a method in the figure lines ("seam-cut", "closest", "island").
std::string_view uvTransferOptionName(viscera::bake::UvTransferMethod method);

struct UvChoice {
    const viscera::sim::TriMesh* mesh = nullptr;
    std::vector<viscera::bake::CornerUv> uv;
    /// each method's figures, by its short name (closest, island, seam-cut), in that order
    std::vector<std::pair<std::string, viscera::bake::UvTransferStats>> stats;
};

/// Prints the source, the cut and, for each method, `uv.<method>.<figure> value` lines (triangles,
/// over_two_islands, over_a_seam, flipped, angle_p50/p95/max, area_p50/p95/max,
/// over_threshold_pct, uv_error_mean/p95/max, seconds); writes the checker preview (source,
/// closest point, seam cutting) when `preview` is set. Returns the surface and UVs of `chosen`.
UvChoice reportUvTransfers(const std::vector<viscera::bake::RemeshPart>& parts, const viscera::bake::RemeshResult& r,
                           viscera::bake::UvTransferMethod chosen, const std::optional<std::string>& preview);
