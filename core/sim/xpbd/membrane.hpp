#pragma once
/// Membrane (stretch) model of a fascia layer [A §4.2]: a triangle with rest area A and in-plane
/// Green strain ε (2 × 2, see strain_limit.hpp) stores
///     E = A · k/2 · (ε_00² + ε_11² + 2 ε_01²)          (k: stretch stiffness, N/m)
/// i.e. a St. Venant–Kirchhoff membrane with zero Poisson ratio. As XPBD constraints:
///     C = (ε_00, ε_11, √2 ε_01),   α = 1/(k A) each,
/// solved one after the other (the rest state, C = 0, is a fixed point). No bending stiffness.
#include "sim/xpbd/strain_limit.hpp"

#include <array>

namespace viscera::sim {

/// D_m⁻¹ (1/m) of a triangle in an orthonormal frame of its plane (axis 0 along x_1 − x_0).
/// False for a degenerate triangle.
bool triangleRestDmInv(const std::array<Vec3, 3>& rest, Mat2& M);

/// The three membrane constraints and, when grad is not null, (*grad)[c][k] = ∂C_c/∂x_k.
std::array<double, 3> membraneConstraints(const std::array<Vec3, 3>& x, const Mat2& M,
                                          std::array<std::array<Vec3, 3>, 3>* grad = nullptr);

} // namespace viscera::sim
