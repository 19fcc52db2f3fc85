#pragma once
/// Internal to viscera::bake: the topology check every closed input surface passes before CGAL
/// sees it (tetrahedralization, skeletonization).
#include "sim/mesh/tri_mesh.hpp"

#include <string>

namespace viscera::bake::detail {

/// Non-empty, finite coordinates, triangle indices in range (indices of `surface` in every
/// message), then closed, consistently oriented, manifold: every edge in exactly two triangles
/// traversing it in opposite directions, every vertex a single fan. Throws viscera::InputError
/// "<label>: surface is not closed: edge (a, b) belongs to only one triangle (t)" and the like.
void checkInputSurface(const std::string& label, const sim::TriMesh& surface);

} // namespace viscera::bake::detail
