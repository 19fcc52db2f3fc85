#pragma once
/// Rotation extraction by the exponential-map update of [A eq. 5.17–5.18] (after Müller et al.,
/// "A robust method to extract the rotational part of deformations", 2016), and the polar
/// decomposition it replaces, used as the reference and as the fallback.
///
/// The update maximises tr(Rᵀ A) over rotations R: each iteration computes
///   ω = Σ_k r_k × a_k / (|Σ_k r_k · a_k| + ε)          [A eq. 5.18]
/// (r_k, a_k the columns of R and A) and sets R ← φ(ω) R [A eq. 5.17], φ the rotation by |ω|
/// about ω/|ω| (Rodrigues). For det A > 0 the fixed point is the rotation of the polar
/// decomposition A = R S; for rank-2 A (a planar point set) it is the unique rotation that
/// best matches the two informative directions; for rank ≤ 1 the undetermined part of R stays
/// where it was. After each update R is re-orthonormalised by one Newton–Schulz step
/// R ← R (3I − RᵀR)/2 so that round-off never accumulates across frames.
///
/// All functions are O(1), allocation-free, and never produce NaN from finite input.
#include "sim/mesh/tri_mesh.hpp"

namespace viscera::sim {

using Mat3 = Eigen::Matrix3d;

/// φ(ω): rotation by angle |ω| (radians) about ω/|ω| (Rodrigues' formula; Taylor series below
/// |ω| = 1e-4, so φ(0) = I exactly).
Mat3 expMapRotation(const Vec3& omega);

/// ω of [A eq. 5.18] for the current estimate R of the rotation of A.
Vec3 expMapIncrement(const Mat3& A, const Mat3& R, double epsilon = 1e-9);

struct ExpMapOptions {
    int maxIterations = 4;    ///< iterations of eq. 5.17 (>= 0)
    double epsilon = 1e-9;    ///< safety term of eq. 5.18 (> 0)
    double tolerance = 1e-12; ///< stop when |ω| <= tolerance, radians (>= 0)
};

/// Runs up to maxIterations updates R ← φ(ω) R on A from the given R (warm start); returns the
/// number of updates applied. R must be a rotation on entry. Non-finite A leaves R unchanged and
/// returns -1.
int refineRotationExpMap(const Mat3& A, Mat3& R, const ExpMapOptions& options = {});

/// Rotation of the polar decomposition A = R S from an SVD A = U Σ Vᵀ (Eigen::JacobiSVD):
/// R = U diag(1, 1, det(U Vᵀ)) Vᵀ, the rotation closest to A in the Frobenius norm (so a
/// reflection in A is resolved through its smallest singular direction, and rank-2 A still has a
/// unique answer). Throws std::invalid_argument on non-finite A.
Mat3 polarRotation(const Mat3& A);

/// Angle of the rotation Raᵀ Rb, radians in [0, π] (robust near 0 and π).
double rotationAngleBetween(const Mat3& Ra, const Mat3& Rb);

} // namespace viscera::sim
