#pragma once
/// Anisotropic strain limiting [A §4.3.4]: constraints on entries of the Green strain
///     ε = ½ (FᵀF − I)                                          [A eq. 4.21]
/// measured in material axes, C = ε_ij − s_ij, either unilateral (ε_ij ≤ upper, ε_ij ≥ lower) or
/// bilateral (ε_ij = s when lower == upper), hard (compliance 0) or compliant.
///
/// Tets: F = Ds Dm⁻¹ A with A the body's orthonormal material axes (columns, rest frame), so
/// ε_ij is the strain along axes i, j. Gradient with respect to vertex k = 1..3 (vertex 0 takes
/// minus their sum), with M = Dm⁻¹ A and f_c the columns of F [A eq. 4.22]:
///     ∂ε_ij/∂x_k = ½ (M_{k−1,i} f_j + M_{k−1,j} f_i).
/// Triangles (fascia, membranes) [A eq. 4.23–4.25]: the tangent T and bitangent B of the UV map,
///     (T, B) = (x_1 − x_0, x_2 − x_0)(u_1 − u_0, u_2 − u_0)⁻¹,
/// are made orthonormal in the triangle plane (t = T/|T|, b = the part of B orthogonal to t,
/// normalised) so that the rest strain is exactly zero; D'_m = (t, b)ᵀ(x_1 − x_0, x_2 − x_0) and
/// F = D_s D'_m⁻¹ (3 × 2). Axis 0 is the u direction exactly, axis 1 the in-plane direction
/// perpendicular to it on the side of +v.
///
/// XPBD treatment: a unilateral constraint keeps its multiplier on the admissible side
/// (upper: λ ≤ 0, lower: λ ≥ 0), so it acts only while violated or while pushing.
#include "sim/material/constraint_model.hpp"
#include "sim/mesh/tri_mesh.hpp"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace viscera::sim {

using Vec2 = Eigen::Vector2d;
using Mat2 = Eigen::Matrix2d;

struct StrainLimit {
    int i = 0, j = 0; ///< Green-strain entry in material axes: 0..2 for tets, 0..1 for triangles
    double lower = -std::numeric_limits<double>::infinity(); ///< ε_ij ≥ lower; −∞ = no lower limit
    double upper = std::numeric_limits<double>::infinity();  ///< ε_ij ≤ upper; +∞ = no upper limit
    /// 0 = hard. Tets: 1/Pa (per unit rest volume, energy V C²/(2α));
    /// triangles: m/N (per unit rest area, energy A C²/(2α)).
    double compliance = 0;
};

/// Strain limits of a tet body. Lower and upper limits of one entry become two unilateral
/// constraints; lower == upper one bilateral constraint.
struct TetStrainLimits {
    Mat3 axes = Mat3::Identity(); ///< orthonormal material axes (columns), rest frame
    std::vector<StrainLimit> limits;
    std::vector<int32_t> tets; ///< tets the limits apply to; empty = all
};

/// Strain limits of a triangle surface, in the UV frame of each triangle (needs per-vertex UVs).
struct TriStrainLimits {
    std::vector<StrainLimit> limits;
    std::vector<int32_t> triangles; ///< triangles the limits apply to; empty = all
};

/// Empty when valid, otherwise the rule that failed. dim = 3 for tets, 2 for triangles.
std::string validate(const StrainLimit& s, int dim);
/// Empty when the columns of axes are orthonormal to 1e-9, otherwise the rule that failed.
std::string validateAxes(const Mat3& axes);

/// M = Dm⁻¹ A for a tet with rest vertices `rest` and material axes A (1/m).
Mat3 tetMaterialDmInv(const std::array<Vec3, 4>& rest, const Mat3& axes);
/// ε_ij of the tet x with M from tetMaterialDmInv; the gradient with respect to x_0..x_3 into
/// grad when not null. Cost: ~60 flops.
double tetGreenStrain(const std::array<Vec3, 4>& x, const Mat3& M, int i, int j, std::array<Vec3, 4>* grad = nullptr);

/// D'_m⁻¹ of the UV frame of a triangle [A eq. 4.23–4.24] (1/m). False when the triangle or its
/// UV image is degenerate.
bool triangleUvDmInv(const std::array<Vec3, 3>& rest, const std::array<Vec2, 3>& uv, Mat2& M);
/// ε_ij (i, j in 0..1) of the triangle x with F = D_s M [A eq. 4.25]; gradient with respect to
/// x_0..x_2 into grad when not null.
double triGreenStrain(const std::array<Vec3, 3>& x, const Mat2& M, int i, int j, std::array<Vec3, 3>* grad = nullptr);

} // namespace viscera::sim
