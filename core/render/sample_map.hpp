#pragma once
/// Light-sampling maps [A §6.3.2, Fig. 6.15]: the per-vertex sample classes (unpainted, 1×, 4×,
/// 8×) a RenderMesh carries in sampleMap, filled over connected regions and measured by area.
/// Everything works on the rest positions, so a map does not change as the tissue deforms.
#include "render/scene_view.hpp"

#include <array>
#include <cstdint>
#include <vector>

namespace viscera::render {

/// Sets the class `samples` (0 erases, else 1, 4 or 8) on every vertex of the faces reachable
/// from face `seedFace` across edges whose two faces' normals differ by at most `maxAngleDeg`
/// (a sharp edge stops the fill) and, when `faceIsland` is given (one UV island id per face),
/// whose two faces lie in the same island (a UV border stops it). Returns the faces reached.
/// Throws std::invalid_argument on a bad class, face index, angle or island size.
size_t fillSampleClass(RenderMesh& mesh, size_t seedFace, int samples, float maxAngleDeg,
                       const std::vector<int32_t>& faceIsland = {});

/// Area (m², at rest) of the mesh in each class, by vertex: each vertex owns a third of its
/// faces' area. Index 0: unpainted, 1: 1×, 2: 4×, 3: 8×.
std::array<double, 4> sampleClassAreas(const RenderMesh& mesh);

} // namespace viscera::render
