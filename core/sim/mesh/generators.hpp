#pragma once
/// Procedural meshes generated in code (sample projects and tests ship no binary assets).
#include "sim/mesh/tet_mesh.hpp"
#include "sim/mesh/tri_mesh.hpp"

#include <array>
#include <memory>

namespace viscera::sim {

struct BoxSpec {
    Vec3 origin = Vec3::Zero();            ///< minimum corner, metres
    Vec3 size = Vec3(0.1, 0.02, 0.04);     ///< edge lengths, metres
    std::array<int, 3> cells = {10, 2, 4}; ///< hexahedral cells per axis (each split into 6 tets)
};

/// Structured tet block: every hex cell split into 6 positively oriented tets sharing its main
/// diagonal (Kuhn subdivision; conforming across cells). Throws std::invalid_argument on
/// non-positive sizes or cell counts.
std::unique_ptr<TetMesh> makeBoxTetMesh(const BoxSpec& spec);

/// Closed outward-oriented triangulated ellipsoid (UV sphere scaled by radii), for meshing tests.
TriMesh makeEllipsoidSurface(const Vec3& center, const Vec3& radii, int slices, int stacks);

/// Closed outward-oriented liver-like surface: an ellipsoid with half-lengths `halfSize` (x long
/// axis), made wedge-shaped (thick at +x, thin at −x, thickness ratio `wedge` in (0, 1]) and bent
/// along y. The map from the sphere is injective, so the surface stays closed and manifold.
TriMesh makeLiverSurface(const Vec3& center, const Vec3& halfSize, double wedge, int slices, int stacks);

/// Closed outward-oriented capped cylinder from `a` to `b` with the given radius.
TriMesh makeTubeSurface(const Vec3& a, const Vec3& b, double radius, int slices, int rings);

/// Closed outward-oriented box surface (12 triangles).
TriMesh makeBoxSurface(const Vec3& min, const Vec3& max);

} // namespace viscera::sim

namespace viscera::sim {

struct HollowTubeSpec {
    Vec3 start = Vec3::Zero();                       ///< axis start, metres
    Vec3 end = Vec3(0, 0, 0.02);                     ///< axis end, metres
    double innerRadius = 0.003, outerRadius = 0.004; ///< metres, 0 < inner < outer
    int slices = 32;                                 ///< cells around (>= 3)
    int layers = 2;                                  ///< cells through the wall (>= 1)
    int rings = 8;                                   ///< cells along the axis (>= 1)
};

/// Structured hollow tube (a vessel): (slices × layers × rings) hexahedral cells in (θ, r, axis),
/// each split into 6 positively oriented tets (Kuhn; conforming, also across θ = 2π). Node index
/// ((ring · (layers + 1)) + layer) · slices + slice. Throws std::invalid_argument on bad sizes.
std::unique_ptr<TetMesh> makeHollowTubeTetMesh(const HollowTubeSpec& spec);

} // namespace viscera::sim
