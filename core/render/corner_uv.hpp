#pragma once
/// Texture coordinates per triangle corner of a body's boundary (anatomy whose UVs were
/// transferred onto the simulation mesh, studio/bake/uv_transfer.hpp): the package entry that
/// "render.materials.<body>.uv" names (meshes/<body>.vuv), its reader and writer side by side,
/// and the split of the body's render mesh at the UV seams.
///
/// File: "VUV1" (4 bytes), the triangle count (uint32, little-endian), then for each boundary
/// triangle of the body's tet mesh, in the order of sim::TetMesh::boundary() (the render mesh's
/// order), its three corners' (u, v) as float32, little-endian: 8 + 24·#F bytes.
#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace viscera::render {

class SceneView;

using CornerUvF = std::array<Eigen::Vector2f, 3>;

/// The largest |u| or |v| accepted (a texture repeated this many times at most).
inline constexpr float kMaxCornerUv = 1024.0f;

/// The bytes of a corner-UV entry. Throws std::invalid_argument when a value is not finite or
/// beyond kMaxCornerUv.
std::string cornerUvBytes(const std::vector<CornerUvF>& uv);

/// Reads a corner-UV entry of a body with `triangles` boundary triangles. Throws
/// viscera::InputError "<origin>: <rule>" (wrong magic, a count other than `triangles`, a size
/// other than the count gives, a value not finite or beyond kMaxCornerUv, naming the triangle).
std::vector<CornerUvF> parseCornerUv(std::string_view bytes, const std::string& origin, size_t triangles);

/// Gives the body mesh named `target` of `view` (RenderMesh::Source::Body, boundary order) the
/// UVs: a render vertex per distinct (vertex, UV) pair, so a seam splits the vertices there (the
/// copies move with their node and share its normal). Returns the meshes changed (0 or 1).
/// Throws std::invalid_argument when the triangle count differs from the mesh's.
size_t applyCornerUv(SceneView& view, const std::string& target, const std::vector<CornerUvF>& uv);

} // namespace viscera::render
