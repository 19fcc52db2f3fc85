#pragma once
/// Refining a tissue layer cut from a body's boundary, so its edges can be finer than the tets'.
#include "sim/mesh/tri_mesh.hpp"

namespace viscera::studio {

/// `times` rounds of midpoint subdivision (each triangle into four at its edge midpoints). The new
/// vertices lie on the old flat triangles, so the layer still lies on the body's boundary and
/// attaches to it as before; edges halve each round. times 0 returns the mesh unchanged.
sim::TriMesh midpointSubdivide(const sim::TriMesh& mesh, int times);

} // namespace viscera::studio
