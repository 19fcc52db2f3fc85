#pragma once
/// Triangle surface mesh: geometry (#V × 3, metres, world frame) and triangles (#F × 3 vertex
/// indices, counter-clockwise seen from outside). Used for fascia layers, imported surfaces and
/// the boundary of a TetMesh.
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace viscera::sim {

using Vec3 = Eigen::Vector3d;
using Tri = std::array<int32_t, 3>;

class TriMesh {
public:
    TriMesh() = default;
    /// Validates and builds. Throws std::invalid_argument naming the rule and element:
    /// no triangles, non-finite coordinates, index out of range, repeated vertex in a triangle.
    /// `origin` (a file name or function) prefixes the message.
    static TriMesh fromArrays(std::vector<Vec3> positions, std::vector<Tri> triangles,
                              const std::string& origin = "sim::TriMesh::fromArrays()");

    const std::vector<Vec3>& positions() const { return m_positions; }
    std::vector<Vec3>& positions() { return m_positions; }
    const std::vector<Tri>& triangles() const { return m_triangles; }
    size_t vertexCount() const { return m_positions.size(); }
    size_t triangleCount() const { return m_triangles.size(); }

    /// Area-weighted unit normal of triangle i (zero vector for a degenerate triangle).
    Vec3 triangleNormal(size_t i) const;
    double area() const;
    /// Signed enclosed volume (divergence theorem); positive for a closed outward-oriented mesh.
    double signedVolume() const;
    /// True when every edge is shared by exactly two triangles with opposite orientation.
    bool isClosedOriented() const;
    /// Axis-aligned bounds, {min, max}.
    std::array<Vec3, 2> bounds() const;

private:
    std::vector<Vec3> m_positions;
    std::vector<Tri> m_triangles;
};

/// Barycentric coordinates of p in triangle (a, b, c), projected onto its plane [B eq. 2.3].
Eigen::Vector3d barycentric(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& p);

} // namespace viscera::sim
