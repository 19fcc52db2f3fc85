#pragma once
/// Adaptive circumspheres of surface triangles [A §5.2.1–5.2.4].
///
/// A triangle's circumsphere passes through its three vertices; its centre lies on the line
/// through the circumcentre x_c along the outward normal N_c, moved inwards by
///     s = φ R_b cot θ H3(K) + ς ε                                             [A eq. 5.7]
/// (C_cir = x_c − N_c s), where R_b is the circumradius, θ the safe angle (half-angle of the
/// cone from the centre to the circumcircle when H3 = 1, ε = 0 and φ = 1 [A eq. 5.2]), H3 the
/// cubic Hermite curvature factor [A eq. 5.4–5.5] that goes from 1 on flat surface to 0 at the
/// curvature threshold h (the sphere then shrinks to the circumcircle's own sphere, radius R_b),
/// ε the triangle's strain energy factor and ς its user scale [A eq. 5.7]. The radius is
/// √(R_b² + s²). The "converging surface" (the cap above the triangle) has height
/// √(R_b² + s²) − s, which is R_b tan(θ/2) for H3 = 1, ε = 0, φ = 1.
///
/// Units: metres, curvature 1/m, ε dimensionless in [0, 1) (saturated strain energy density with
/// unit modulus), ς metres.
#include "sim/mesh/tri_mesh.hpp"

#include <vector>

namespace viscera::sim {

/// Cubic Hermite segment on [x0, x1] with end values y0, y1 and end slopes m0, m1 [A eq. 5.4],
/// clamped to the end values outside the interval.
struct CubicHermite {
    double x0 = 0, x1 = 1, y0 = 0, y1 = 1, m0 = 0, m1 = 0;
    double value(double x) const;
    double derivative(double x) const; ///< 0 outside [x0, x1]
};

/// H3(K) of [A eq. 5.4–5.5]: (0, 1) with slope 0 to (h, 0) with slope 0; 0 for K >= h, 1 for
/// K <= 0. Throws std::invalid_argument on h <= 0.
CubicHermite curvatureHermite(double threshold);

struct CircumsphereParams {
    double safeAngle = 0.5235987755982988; ///< θ, rad, in (0, π/2) (default 30°)
    double scale = 1.0;                    ///< φ, >= 0
    double curvatureThreshold = 150.0;     ///< h, 1/m (> 0): sphere = circumcircle sphere above it
    double energyScale = 0.005;            ///< ς, m: largest extra inward offset (ε < 1), >= 0
    /// δ, >= 0: refresh H3(K) and ε when |S/S_ref − 1| >= δ. Default 0.7, the thesis' value for
    /// scenes that need stability, efficiency and accuracy together [A §5.2.6] and the scene
    /// default (interaction.hpp); small δ refreshes often, and every refresh reshapes the sphere
    /// under a resting tool (bench_collision's δ sweep shows the jitter that adds).
    double updateThreshold = 0.7;
};

/// Empty when valid, otherwise the rule that failed.
std::string validate(const CircumsphereParams& p);

struct Circumcircle {
    Vec3 centre = Vec3::Zero();  ///< x_c, m
    Vec3 normal = Vec3::UnitZ(); ///< N_c, unit, the triangle's (counter-clockwise) normal
    double radius = 0;           ///< R_b, m
    double area = 0;             ///< m²
    bool valid = false;          ///< false for a degenerate (zero-area) triangle
};
/// Circumcircle of triangle (a, b, c). Degenerate or needle-like triangles (circumradius above
/// 4 × the longest edge): the centroid and the largest vertex distance stand in, valid = false.
Circumcircle circumcircle(const Vec3& a, const Vec3& b, const Vec3& c);

struct Sphere {
    Vec3 centre = Vec3::Zero(); ///< m
    double radius = 0;          ///< m
    /// Safe cone [A §5.2.1]: the cone from the centre through the triangle's circumcircle, axis
    /// coneAxis (the triangle's normal), half-angle acos(coneCos). Only its part of the sphere
    /// (the converging surface) stands for the tissue surface; the rest lies inside the tissue.
    /// coneCos = −1: the whole sphere counts (bounding sphere).
    Vec3 coneAxis = Vec3::UnitZ();
    double coneCos = -1;
    /// Whether the direction from the centre to point p lies in the safe cone (p ≠ centre).
    bool inSafeCone(const Vec3& p) const;
};

/// Inward offset s of [A eq. 5.7] for the given curvature factor H3(K) and energy factor ε.
double circumsphereOffset(double circumradius, double h3, double energy, const CircumsphereParams& p);
/// φ cot θ of [A eq. 5.5]: the inward offset per metre of circumradius where H3 = 1.
double offsetPerRadius(const CircumsphereParams& p);
/// The same offset with φ cot θ already evaluated (offsetPerRadius), for the per-sweep loops.
inline double circumsphereOffset(double circumradius, double h3, double energy, double perRadius, double energyScale) {
    return perRadius * circumradius * h3 + energyScale * energy;
}
/// The circumsphere: centre x_c − N_c s, radius √(R_b² + s²).
Sphere circumsphere(const Circumcircle& cc, double offset);
/// Bounding sphere of [MO06] used for comparison: centroid, largest vertex distance.
Sphere boundingSphere(const Vec3& a, const Vec3& b, const Vec3& c);

/// Energy factor ε of a triangle, in [0, 1): e / (1 + e) with e = ‖E‖_F² the strain energy
/// density (unit modulus) of its Green–Lagrange strain E = ½(FᵀF − I) in the rest triangle's
/// plane (e = ½(s² − 1)² for a uniform in-plane stretch s; 0 for a rigid motion). The
/// saturation keeps the sphere bounded: with e itself, a deep contact grows the sphere, which
/// pushes harder, which grows e (a run-away measured in bench_collision at δ = 0). 0 for a
/// degenerate rest triangle, 1 for a non-finite strain.
double triangleEnergyFactor(const std::array<Vec3, 3>& rest, const std::array<Vec3, 3>& current);

/// Discrete curvature of a triangle surface: K_v = Σ_{edges e at v} ½ |β_e| |e| / A_v, β_e the
/// dihedral angle between the normals across e and A_v a third of the area around v; an estimate
/// of |κ1| + |κ2| (1/r on a cylinder of radius r, 0 on a plane). Boundary and non-manifold edges
/// contribute nothing. Built once per topology; queries O(valence).
class SurfaceCurvature {
public:
    SurfaceCurvature() = default;
    SurfaceCurvature(size_t vertexCount, const std::vector<Tri>& triangles);
    /// K at vertex v for the positions x (#V of the triangles' index space), 1/m.
    double vertexCurvature(int32_t v, const std::vector<Vec3>& x) const;
    /// Mean of the three vertex curvatures of triangle t (the curvature at the circumcentre).
    double triangleCurvature(int32_t t, const std::vector<Vec3>& x) const;

private:
    struct Edge {
        int32_t v0, v1, t0, t1; ///< t1 = -1 on a boundary edge
    };
    std::vector<Tri> m_tris;
    std::vector<Edge> m_edges;
    std::vector<uint32_t> m_vEdgeStart, m_vTriStart; ///< CSR, #V + 1
    std::vector<int32_t> m_vEdges, m_vTris;
};

} // namespace viscera::sim
