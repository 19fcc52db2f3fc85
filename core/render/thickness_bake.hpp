#pragma once
/// Thickness bake for subsurface scattering [A §6.3.1]: from each vertex, rays are cast into the
/// cone of 37° around the inward normal (−n) against a triangle mesh; the thickness is the mean
/// distance to the first hit (rays that escape count as `maxThickness`). Done once, in the rest
/// configuration, like the thesis's pre-computed thickness map (here stored per vertex).
#include "render/image.hpp"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <vector>

namespace viscera::render {

/// Bounding-volume hierarchy over a triangle soup for ray casts. Cost: build O(T log T); a ray
/// O(log T) typically.
class TriangleBvh {
public:
    /// positions: #V × 3 (m); triangles: #F × 3 indices. Throws std::invalid_argument on an index
    /// out of range.
    TriangleBvh(const std::vector<Eigen::Vector3f>& positions, const std::vector<std::array<uint32_t, 3>>& triangles);
    /// Distance along the unit direction `dir` to the nearest hit in (tMin, tMax], or a negative
    /// value when there is none.
    float raycast(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir, float tMin, float tMax) const;
    size_t triangleCount() const { return m_tris.size(); }

private:
    struct Node {
        Eigen::Vector3f lo, hi;
        int32_t left = -1, right = -1; ///< children; leaves have left < 0
        uint32_t first = 0, count = 0; ///< triangle range for leaves
    };
    int32_t build(uint32_t first, uint32_t count);
    std::vector<Eigen::Vector3f> m_v;
    std::vector<std::array<uint32_t, 3>> m_tris;
    std::vector<Node> m_nodes;
};

struct ThicknessBakeSettings {
    int rays = 12;              ///< per vertex, within 37° of −n (deterministic spiral pattern)
    float maxThickness = 0.05f; ///< m, for rays that leave the mesh
    float offset = 1e-5f;       ///< m, start offset along −n
};

/// Thickness per vertex (m) of the points `positions` with unit outward `normals` against `target`.
std::vector<float> bakeThickness(const std::vector<Eigen::Vector3f>& positions,
                                 const std::vector<Eigen::Vector3f>& normals, const TriangleBvh& target,
                                 const ThicknessBakeSettings& settings = {});

/// The thickness map of a textured mesh [A §6.3.1]: a `size` × `size` texture in its UV space
/// (v = 0 at the image's bottom row), each texel covered by a triangle holding the thickness of
/// the surface point under it (barycentric position and normal, the same cone of rays as
/// bakeThickness), encoded as thickness / `range` in R = G = B (8-bit; A = 255). Texels no
/// triangle covers take their nearest covered neighbour's value within 4 texels (no dark seams
/// under filtering), else 0. Triangles spanning more than half the texture (a wrapped seam) are
/// skipped. Throws std::invalid_argument for #uv != #positions, an index out of range, size not
/// in [1, 4096] or range <= 0. `covered`, when given, receives the texels covered by a triangle.
Image bakeThicknessTexture(const std::vector<Eigen::Vector3f>& positions, const std::vector<Eigen::Vector3f>& normals,
                           const std::vector<std::array<uint32_t, 3>>& triangles,
                           const std::vector<Eigen::Vector2f>& uv, const TriangleBvh& target, int size, float range,
                           const ThicknessBakeSettings& settings = {}, size_t* covered = nullptr);

} // namespace viscera::render
