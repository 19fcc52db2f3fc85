#pragma once
/// The .vweights text format: one stiffness weight per tet node (case packages; the output of
/// skeleton-based stiffness painting [A §4.3.5], read into TetBodyDesc::nodeWeights):
///
///   vweights 1
///   nodes <N>
///   <w>                    N lines, one weight per node in node order, finite and > 0
///
/// Lines starting with '#' and blank lines are ignored; a value may be followed by a '#' comment.
/// Parsing is strict: every error names the origin (file name), the line and the rule, e.g.
/// "vessel.vweights: line 7: weight of node 4 is -2 (must be finite and > 0)". Values are
/// written with 17 significant digits and read back bit-identical.
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace viscera::sim {

/// Parses .vweights text; throws viscera::InputError. With `expectedNodes`, the node count must
/// match it ("<origin>: line 2: file has 10 nodes, the mesh has 12").
std::vector<double> parseNodeWeights(std::string_view text, const std::string& origin,
                                     std::optional<size_t> expectedNodes = std::nullopt);
/// Serializes weights; throws std::invalid_argument ("sim::formatNodeWeights(): weight of node 3
/// is nan (must be finite and > 0)") when there are none or one is not finite and > 0.
std::string formatNodeWeights(const std::vector<double>& weights);

/// Reads a file (the file name is the origin of messages); throws viscera::InputError.
std::vector<double> readNodeWeights(const std::filesystem::path& path,
                                    std::optional<size_t> expectedNodes = std::nullopt);
/// Atomic write (temporary file, fsync, rename): a crash leaves the old file or the new one.
void writeNodeWeights(const std::filesystem::path& path, const std::vector<double>& weights);

} // namespace viscera::sim
