#include "sim/suture/needle_curve.hpp"

#include <gtest/gtest.h>

#include <numbers>
#include <random>

using namespace viscera::sim;

TEST(NeedleCurve, ArcLengthParametrizationAndTangent) {
    const NeedleCurve a = NeedleCurve::arc(Vec3(1, 2, 3), Vec3(1, 0, 0), Vec3(0, 1, 0.2), 0.01);
    EXPECT_NEAR((a.point(0) - Vec3(1.01, 2, 3)).norm(), 0, 1e-15);
    const double h = 1e-7;
    for (double s : {-0.02, 0.0, 0.005, 0.0314}) {
        const Vec3 fd = (a.point(s + h) - a.point(s - h)) / (2 * h);
        EXPECT_NEAR((fd - a.tangent(s)).norm(), 0, 1e-7); // unit speed: arc length parameter
        EXPECT_NEAR(a.tangent(s).norm(), 1, 1e-14);
        EXPECT_NEAR((a.point(s) - a.p).norm(), a.r, 1e-15);
    }
    const NeedleCurve l = NeedleCurve::straight(Vec3(0, 0, 0), Vec3(0, 0, 2));
    EXPECT_NEAR((l.point(0.5) - Vec3(0, 0, 0.5)).norm(), 0, 1e-15);
}

TEST(NeedleCurve, PlaneCrossingsAreRootsInOrder) {
    std::mt19937 rng(2);
    std::uniform_real_distribution<double> u(-1, 1);
    for (int trial = 0; trial < 500; ++trial) {
        const NeedleCurve c = NeedleCurve::arc(Vec3(u(rng), u(rng), u(rng)), Vec3(u(rng), u(rng), u(rng)),
                                               Vec3(u(rng), u(rng), u(rng)), 0.5 + 0.4 * u(rng));
        const Vec3 n = Vec3(u(rng), u(rng), u(rng)).normalized();
        const double d = 0.5 * u(rng);
        const double a = u(rng), b = a + 4.0 * std::abs(u(rng));
        double roots[8];
        const int k = c.planeCrossings(n, d, a, b, roots, 8);
        for (int i = 0; i < k; ++i) {
            EXPECT_GT(roots[i], a);
            EXPECT_LE(roots[i], b);
            EXPECT_NEAR(n.dot(c.point(roots[i])), d, 1e-12);
            if (i) {
                EXPECT_LE(roots[i - 1], roots[i]);
            }
        }
        // Sign changes of n·s(α) − d on a fine grid are all found.
        int changes = 0;
        const int N = 4000;
        for (int j = 0; j < N; ++j) {
            const double s0 = a + (b - a) * j / N, s1 = a + (b - a) * (j + 1) / N;
            if ((n.dot(c.point(s0)) - d) * (n.dot(c.point(s1)) - d) < 0) ++changes;
        }
        EXPECT_EQ(changes, k) << trial;
    }
}

TEST(NeedleCurve, ClosestParameter) {
    const NeedleCurve c = NeedleCurve::arc(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), 1.0);
    EXPECT_NEAR(c.closestParameter(Vec3(0, 2, 0), 0, std::numbers::pi), std::numbers::pi / 2, 1e-12);
    EXPECT_NEAR(c.closestParameter(Vec3(0, -2, 0), 0, 1.0), 0.0, 1e-12);
    const NeedleCurve l = NeedleCurve::straight(Vec3::Zero(), Vec3::UnitZ());
    EXPECT_NEAR(l.closestParameter(Vec3(3, 1, 0.25), 0, 1), 0.25, 1e-15);
}
