#pragma once
/// Coupling between tissue layers [A §4.2]: a particle tied to a barycentric point of other
/// particles,
///     C = x_p − Σ_k b_k x_k   (3-vector, m),   ∂C/∂x_p = I,   ∂C/∂x_k = −b_k I,
/// with compliance α (m/N; energy |C|²/(2α); 0 = hard). The three components share the
/// effective mass w_p + Σ b_k² w_k and are solved together.
///   - fascia on fat: each fascia vertex → the closest point of the fat boundary (a triangle and
///     its barycentric coordinates, [A eq. 4.1]);
///   - embedded tissue in fat: each embedded node → the fat tet that contains it (a cage, as in
///     free-form deformation), with its four barycentric coordinates.
#include "sim/mesh/tet_mesh.hpp"
#include "sim/util/error.hpp"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <vector>

namespace viscera::sim {

/// C = x_p − Σ_{k<n} b_k x_k for n = 3 or 4 targets.
Vec3 couplingResidual(const Vec3& xp, const Vec3* targets, const double* bary, int n);

/// Closest point to p on triangle (a, b, c); its barycentric coordinates (≥ 0, sum 1) into bary.
Vec3 closestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, Eigen::Vector3d& bary);

struct BoundaryProjection {
    int32_t point = -1;                             ///< index into the query points
    std::array<int32_t, 3> vertices{};              ///< cage mesh vertices of the boundary triangle
    Eigen::Vector3d bary = Eigen::Vector3d::Zero(); ///< closest point = Σ bary_k x_k
    double distance = 0;                            ///< m
};

/// For every point within maxDistance (m) of the boundary of `cage`, the closest boundary point;
/// farther points are left out. Uses the mesh's level-1 adjacency only. Cost: a uniform grid,
/// about O(#points + #boundary triangles).
std::vector<BoundaryProjection> projectOntoBoundary(const TetMesh& cage, const std::vector<Vec3>& points,
                                                    double maxDistance);

struct CageLocation {
    int32_t point = -1;                             ///< index into the query points
    int32_t tet = -1;                               ///< cage tet
    Eigen::Vector4d bary = Eigen::Vector4d::Zero(); ///< point = Σ bary_k x_k (exact at rest)
};

/// For every point, the cage tet containing it (or, for a point outside the cage by at most
/// tolerance metres, the nearest tet). Throws std::invalid_argument
/// ("sim::locateInCage(): point 12 lies 0.004 m outside the cage") for a point farther out.
/// What locateInCage throws for a point outside the cage: what() is the full message, `point` and
/// `howFar` ("lies 0.004 m outside the cage") let a caller word it for its own elements.
struct OutsideCageError : PreconditionError {
    OutsideCageError(const std::string& where, int32_t point, const std::string& howFar)
        : PreconditionError(where, "point " + std::to_string(point) + " " + howFar), point(point), howFar(howFar) {}
    int32_t point;
    std::string howFar;
};
std::vector<CageLocation> locateInCage(const TetMesh& cage, const std::vector<Vec3>& points, double tolerance);

} // namespace viscera::sim
