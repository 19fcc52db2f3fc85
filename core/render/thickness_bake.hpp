#pragma once
/// Thickness bake for subsurface scattering [A §6.3.1]: from each vertex, rays are cast into the
/// cone of 37° around the inward normal (−n) against a triangle mesh; the thickness is the mean
/// distance to the first hit (rays that escape count as `maxThickness`). Done once, in the rest
/// configuration, like the thesis's pre-computed thickness map (here stored per vertex).
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

} // namespace viscera::render
