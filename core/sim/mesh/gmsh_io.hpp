#pragma once
/// Tetrahedral meshes from other tools [issue 57 item 7]: Gmsh's .msh (format 2.2 and 4.1, ASCII)
/// and VTK's unstructured grid .vtu (ASCII data arrays). Only linear tetrahedra are taken (Gmsh
/// element type 4, VTK cell type 10); points, lines and triangles (the surfaces Gmsh saves with
/// the volume) are skipped, and any other volume element (a 10-node tetrahedron, a hexahedron, a
/// prism) is refused with its number and type, since dropping it would leave a hole. Nodes no
/// tetrahedron uses are dropped; a tetrahedron of negative volume has two nodes swapped (the
/// positive orientation TetMesh expects). Coordinates are multiplied by `scale` (a file in
/// centimetres: 0.01). Errors name the file, the line (msh) or the array (vtu) and the rule:
///   "liver.msh: line 12: element 7 is of type 11 (10-node tetrahedron): only linear
///    tetrahedra (type 4) are read"
/// then TetMesh::fromArrays' rules (a facet shared by three tetrahedra, ...). Binary files and
/// compressed or appended VTK data are refused with how to save them as text.
#include "sim/mesh/tet_mesh.hpp"

#include <filesystem>
#include <memory>
#include <string>
#include <string_view>

namespace viscera::sim {

/// Throws viscera::InputError.
std::unique_ptr<TetMesh> parseGmshTets(std::string_view text, const std::string& origin, double scale = 1.0);
std::unique_ptr<TetMesh> parseVtuTets(std::string_view text, const std::string& origin, double scale = 1.0);
/// By the file's extension (.msh, .vtu, .vtet; case-insensitive); at most 512 MiB.
std::unique_ptr<TetMesh> readTetFile(const std::filesystem::path& path, double scale = 1.0);
/// Whether readTetFile reads files of this name's extension.
bool isTetFile(const std::filesystem::path& path);

} // namespace viscera::sim
