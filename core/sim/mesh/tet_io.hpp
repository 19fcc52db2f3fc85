#pragma once
/// The .vtet text format for tetrahedral meshes (case packages, tests, tools):
///
///   vtet 1
///   vertices <N>
///   <x> <y> <z>            N lines, metres
///   tets <M>
///   <a> <b> <c> <d>        M lines, 0-based vertex indices, positive orientation
///
/// Lines starting with '#' and blank lines are ignored. Parsing is strict: every error names the
/// origin (file name), the line and the rule, e.g. "liver.vtet: line 14: vertex 3 has a
/// non-finite coordinate". Mesh-level rules are those of TetMesh::fromArrays.
#include "sim/mesh/tet_mesh.hpp"

#include <filesystem>
#include <memory>
#include <string>
#include <string_view>

namespace viscera::sim {

/// Parses .vtet text; throws viscera::InputError.
std::unique_ptr<TetMesh> parseVtet(std::string_view text, const std::string& origin);
/// Serializes geometry and topology (17 significant digits, round-trips exactly).
std::string formatVtet(const TetMesh& mesh);

std::unique_ptr<TetMesh> readVtet(const std::filesystem::path& path);
/// Atomic write.
void writeVtet(const std::filesystem::path& path, const TetMesh& mesh);

/// The .vtri text format for triangle surfaces (fascia layers): as .vtet with a "vtri 1" header
/// and "triangles <M>" followed by M lines of 3 indices (counter-clockwise seen from outside).
TriMesh parseVtri(std::string_view text, const std::string& origin);
std::string formatVtri(const TriMesh& mesh);

} // namespace viscera::sim
