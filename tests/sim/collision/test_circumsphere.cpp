#include "sim/collision/circumsphere.hpp"
#include "sim/mesh/generators.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace viscera::sim;

TEST(Circumsphere, CircumcircleOfARightTriangle) {
    const Circumcircle cc = circumcircle(Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(0, 2, 0));
    EXPECT_TRUE(cc.valid);
    EXPECT_LT((cc.centre - Vec3(1, 1, 0)).norm(), 1e-15);
    EXPECT_NEAR(cc.radius, std::sqrt(2.0), 1e-15);
    EXPECT_LT((cc.normal - Vec3::UnitZ()).norm(), 1e-15);
    EXPECT_NEAR(cc.area, 2.0, 1e-15);
}

TEST(Circumsphere, DegenerateTriangleFallsBackToBoundingSphere) {
    const Circumcircle line = circumcircle(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0));
    EXPECT_FALSE(line.valid);
    EXPECT_LT((line.centre - Vec3(1, 0, 0)).norm(), 1e-15);
    EXPECT_NEAR(line.radius, 1.0, 1e-15);
    EXPECT_TRUE(line.normal.allFinite());
    const Circumcircle sliver = circumcircle(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 1e-9, 0));
    EXPECT_FALSE(sliver.valid);
    EXPECT_TRUE(std::isfinite(sliver.radius));
}

// [A eq. 5.2]: C = x_c − N φ R_b cot θ; with φ = 1 the cone from C to the circumcircle has
// half-angle θ, and the sphere passes through the three vertices.
TEST(Circumsphere, SafeAngleOfEquation52) {
    const Vec3 a(0.01, 0.002, 0.03), b(0.018, 0.004, 0.031), c(0.012, 0.011, 0.029);
    const Circumcircle cc = circumcircle(a, b, c);
    for (double thetaDeg : {10.0, 30.0, 45.0, 70.0})
        for (double phi : {0.5, 1.0, 2.0}) {
            CircumsphereParams p;
            p.safeAngle = thetaDeg * M_PI / 180;
            p.scale = phi;
            const double s = circumsphereOffset(cc.radius, 1.0, 0.0, p);
            EXPECT_NEAR(s, phi * cc.radius / std::tan(p.safeAngle), 1e-15);
            const Sphere sp = circumsphere(cc, s);
            EXPECT_LT((sp.centre - (cc.centre - s * cc.normal)).norm(), 1e-15);
            for (const Vec3& v : {a, b, c})
                EXPECT_NEAR((v - sp.centre).norm(), sp.radius, 1e-14);
            // The centre is on the inner side (against the counter-clockwise normal).
            EXPECT_LT((sp.centre - a).dot(cc.normal), 0);
            if (phi == 1.0) {
                const double cone = std::atan2(cc.radius, (sp.centre - cc.centre).norm());
                EXPECT_NEAR(cone, p.safeAngle, 1e-12);
                // Converging-surface cap height R_b tan(θ/2).
                EXPECT_NEAR(sp.radius - s, cc.radius * std::tan(p.safeAngle / 2), 1e-14);
            }
        }
}

// [A eq. 5.4–5.5]: H3 from (0, 1) to (h, 0) with zero slopes.
TEST(Circumsphere, CurvatureHermiteKnotsAndDerivatives) {
    for (double h : {10.0, 150.0, 1000.0}) {
        const CubicHermite H = curvatureHermite(h);
        EXPECT_EQ(H.value(0), 1.0);
        EXPECT_EQ(H.value(h), 0.0);
        EXPECT_NEAR(H.derivative(0), 0.0, 1e-15);
        EXPECT_NEAR(H.derivative(h), 0.0, 1e-15);
        EXPECT_NEAR(H.value(0.5 * h), 0.5, 1e-15);
        EXPECT_EQ(H.value(-1), 1.0);
        EXPECT_EQ(H.value(2 * h), 0.0);
        for (double t : {0.1, 0.3, 0.7, 0.9}) {
            const double x = t * h, e = 1e-6 * h;
            const double fd = (H.value(x + e) - H.value(x - e)) / (2 * e);
            EXPECT_NEAR(H.derivative(x), fd, 1e-6 / h);
            EXPECT_LT(H.derivative(x), 0); // monotone decreasing
        }
    }
    // General segment: values and slopes at both knots.
    const CubicHermite g{1.0, 3.0, 2.0, -1.0, 0.5, -2.0};
    EXPECT_NEAR(g.value(1.0), 2.0, 1e-15);
    EXPECT_NEAR(g.value(3.0), -1.0, 1e-15);
    EXPECT_NEAR(g.derivative(1.0), 0.5, 1e-14);
    EXPECT_NEAR(g.derivative(3.0), -2.0, 1e-14);
    const double e = 1e-6;
    EXPECT_NEAR((g.value(1.0 + e) - g.value(1.0)) / e, 0.5, 1e-5);
    EXPECT_NEAR((g.value(3.0) - g.value(3.0 - e)) / e, -2.0, 1e-5);
    EXPECT_THROW(curvatureHermite(0.0), std::invalid_argument);
}

// [A eq. 5.5, 5.7]: the curvature factor shrinks the offset to 0 at K >= h; the energy term adds
// ς ε.
TEST(Circumsphere, OffsetOfEquation57) {
    CircumsphereParams p;
    p.curvatureThreshold = 100;
    p.energyScale = 0.004;
    const CubicHermite H = curvatureHermite(p.curvatureThreshold);
    const double Rb = 0.005, base = Rb / std::tan(p.safeAngle);
    EXPECT_NEAR(circumsphereOffset(Rb, H.value(0), 0, p), base, 1e-15);
    EXPECT_NEAR(circumsphereOffset(Rb, H.value(50), 0, p), 0.5 * base, 1e-15);
    EXPECT_NEAR(circumsphereOffset(Rb, H.value(100), 0, p), 0.0, 1e-15);
    EXPECT_NEAR(circumsphereOffset(Rb, H.value(100), 0.25, p), 0.001, 1e-15);
    EXPECT_NEAR(circumsphereOffset(Rb, H.value(50), 0.5, p), 0.5 * base + 0.002, 1e-15);
    // At K >= h the sphere is the circumcircle's own sphere (radius R_b).
    const Circumcircle cc = circumcircle(Vec3(0, 0, 0), Vec3(0.01, 0, 0), Vec3(0, 0.01, 0));
    EXPECT_NEAR(circumsphere(cc, 0.0).radius, cc.radius, 1e-15);
}

TEST(Circumsphere, EnergyFactor) {
    const std::array<Vec3, 3> rest = {Vec3(0, 0, 0), Vec3(0.01, 0, 0), Vec3(0.003, 0.008, 0)};
    // Rigid motion: 0.
    const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
    std::array<Vec3, 3> moved;
    for (int k = 0; k < 3; ++k)
        moved[k] = R * rest[k] + Vec3(1, -2, 0.5);
    EXPECT_NEAR(triangleEnergyFactor(rest, moved), 0.0, 1e-24);
    // Uniform in-plane stretch s: e = ½ (s² − 1)², ε = e / (1 + e).
    for (double s : {0.8, 1.1, 1.5, 3.0}) {
        for (int k = 0; k < 3; ++k)
            moved[k] = R * (s * rest[k]);
        const double e = 0.5 * std::pow(s * s - 1, 2);
        EXPECT_NEAR(triangleEnergyFactor(rest, moved), e / (1 + e), 1e-12) << "s " << s;
    }
    // Monotone in the stretch, bounded by 1.
    for (int k = 0; k < 3; ++k)
        moved[k] = 100.0 * rest[k];
    EXPECT_LT(triangleEnergyFactor(rest, moved), 1.0);
    // Degenerate rest triangle: 0.
    EXPECT_EQ(triangleEnergyFactor({Vec3::Zero(), Vec3::Zero(), Vec3::UnitX()}, moved), 0.0);
}

TEST(Circumsphere, DiscreteCurvatureOnPlaneAndCylinder) {
    // Plane: the top of a box interior is flat.
    const TriMesh box = makeBoxSurface(Vec3::Zero(), Vec3(1, 1, 1));
    SurfaceCurvature boxK(box.vertexCount(), box.triangles());
    // Every box vertex is a corner: positive curvature.
    for (int v = 0; v < 8; ++v)
        EXPECT_GT(boxK.vertexCurvature(v, box.positions()), 0);
    // A flat grid: zero everywhere.
    std::vector<Vec3> grid;
    std::vector<Tri> tris;
    const int n = 6;
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i)
            grid.emplace_back(0.01 * i, 0.01 * j, 0.0);
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const int a = j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
            tris.push_back({a, b, d});
            tris.push_back({a, d, c});
        }
    SurfaceCurvature flat(grid.size(), tris);
    for (int v = 0; v < static_cast<int>(grid.size()); ++v)
        EXPECT_NEAR(flat.vertexCurvature(v, grid), 0.0, 1e-9);
    // Cylinder of radius r: about 1/r on the side, far from the caps.
    const double r = 0.01;
    const TriMesh tube = makeTubeSurface(Vec3(0, 0, 0), Vec3(0, 0, 0.1), r, 48, 20);
    SurfaceCurvature tubeK(tube.vertexCount(), tube.triangles());
    int checked = 0;
    for (int v = 0; v < static_cast<int>(tube.vertexCount()); ++v) {
        const Vec3& p = tube.positions()[v];
        if (p.z() < 0.03 || p.z() > 0.07 || std::hypot(p.x(), p.y()) < 0.9 * r) continue;
        EXPECT_NEAR(tubeK.vertexCurvature(v, tube.positions()), 1 / r, 0.2 / r) << "vertex " << v;
        ++checked;
    }
    EXPECT_GT(checked, 48);
}
