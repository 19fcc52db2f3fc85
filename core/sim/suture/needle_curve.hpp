#pragma once
/// Parametric needle curve with arc-length parameter α [B §3.1.1, eq. 3.4, 3.8, 3.11], world frame.
/// Straight: s(α) = p + α ŵ. Semicircular (any arc): s(α) = p + r cos(α/r) û + r sin(α/r) v̂ with p
/// the circle centre. The needle itself spans α ∈ [0, ℓ] (end at 0, tip at ℓ); the curve is defined
/// for every α, which is what tip tracking uses to follow the sliding tip beyond ℓ.
#include "sim/mesh/tri_mesh.hpp"

#include <Eigen/Core>

namespace viscera::sim {

struct NeedleCurve {
    enum class Kind { Straight, Arc };
    Kind kind = Kind::Straight;
    Vec3 p = Vec3::Zero();  ///< straight: end point; arc: circle centre, m
    Vec3 w = Vec3::UnitX(); ///< straight: unit axis
    Vec3 u = Vec3::UnitX(); ///< arc: unit vector to the end point (α = 0)
    Vec3 v = Vec3::UnitY(); ///< arc: unit vector, u ⟂ v, direction of increasing α
    double r = 0.01;        ///< arc radius, m

    static NeedleCurve straight(const Vec3& p, const Vec3& w);
    static NeedleCurve arc(const Vec3& centre, const Vec3& u, const Vec3& v, double radius);

    Vec3 point(double alpha) const;
    Vec3 tangent(double alpha) const;          ///< unit
    Vec3 normal() const { return u.cross(v); } ///< arc: plane normal

    /// Parameters α in (a, b] at which the curve crosses the plane n·x = d, ascending; returns the
    /// count (0, 1 or 2 for b − a below one turn; up to 2 per turn otherwise, at most `cap`).
    int planeCrossings(const Vec3& n, double d, double a, double b, double* out, int cap) const;
    /// Parameter of the point of the curve nearest to q within [a, b].
    double closestParameter(const Vec3& q, double a, double b) const;
};

} // namespace viscera::sim
