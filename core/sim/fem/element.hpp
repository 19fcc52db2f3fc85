#pragma once
/// Linear tetrahedral element of [B §2.2.1–2.2.2] and the rotation extraction of the corotational
/// method [B §2.2.3].
#include "sim/mesh/tri_mesh.hpp"

#include <Eigen/Core>

#include <array>

namespace viscera::sim {

using Mat3 = Eigen::Matrix3d;
using Vec12 = Eigen::Matrix<double, 12, 1>;
using Mat12 = Eigen::Matrix<double, 12, 12>;

struct LinearTet {
    Mat12 stiffness;                  ///< K_e = v Bᵀ E B, N/m, node-major (3a + i)
    Eigen::Matrix<double, 4, 3> grad; ///< ∇N_a of the four shape functions, 1/m, rest frame
    Mat3 dmInv;                       ///< inverse of the rest edge matrix [x1−x0, x2−x0, x3−x0]
    double volume = 0;                ///< m^3, rest
};

/// Element stiffness from rest positions and Lamé parameters (Pa):
/// K[3a+i, 3b+j] = v (λ ∂_i N_a ∂_j N_b + μ ∂_j N_a ∂_i N_b + μ δ_ij ∇N_a·∇N_b) [B eq. 2.33].
/// Throws std::invalid_argument when the rest volume is not positive.
LinearTet makeLinearTet(const std::array<Vec3, 4>& rest, double lambda, double mu);

/// Strain energy v (μ ε:ε + λ/2 tr(ε)²) of the displacement u (12, metres), J. Its Hessian is
/// `stiffness` (checked by finite differences in the tests).
double linearTetEnergy(const LinearTet& e, const Vec12& u, double lambda, double mu);

/// Deformation gradient F = Ds Dm⁻¹ of the element at positions x (4 nodes).
Mat3 deformationGradient(const LinearTet& e, const std::array<Vec3, 4>& x);

/// The element rotation of the corotational FEM: the polar rotation of F (sim::polarRotation,
/// clip/exp_map_rotation.hpp: det R = +1, an inverted element gets the rotation nearest to F's
/// orthogonal factor), the identity for a non-finite F.
Mat3 elementRotation(const Mat3& F);

} // namespace viscera::sim
