// Thread distance linearization [B eq. 3.34–3.37] against finite differences over a sweep of
// segment lengths (above and below the stabilization ε), and the needle motion decomposition into
// sliding and sticking [B eq. 3.9, 3.12–3.17].
#include "sim/suture/suture_sim.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

using namespace viscera::sim;

TEST(ThreadLinearization, GradientMatchesFiniteDifferencesAcrossLengths) {
    const double eps = 2e-4;
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-1, 1);
    for (double len : {1e-7, 5e-5, 1.5e-4, 1.999e-4, 2.001e-4, 5e-4, 3e-3, 2e-2}) {
        for (int trial = 0; trial < 8; ++trial) {
            const Vec3 ra(u(rng) * 0.01, u(rng) * 0.01, u(rng) * 0.01);
            const Vec3 dir = Vec3(u(rng), u(rng), u(rng)).normalized();
            const Vec3 rb = ra + len * dir;
            const ThreadSegmentLinearization l = linearizeThreadSegment(ra, rb, eps);
            ASSERT_TRUE(std::isfinite(l.length) && l.direction.allFinite() && std::isfinite(l.offset));
            const double h = std::min(1e-9, 0.01 * std::abs(len - eps) + 1e-12);
            Vec3 fd;
            for (int k = 0; k < 3; ++k) {
                Vec3 e = Vec3::Zero();
                e[k] = h;
                fd[k] =
                    (linearizeThreadSegment(ra, rb + e, eps).length - linearizeThreadSegment(ra, rb - e, eps).length) /
                    (2 * h);
            }
            EXPECT_NEAR((fd - l.direction).norm(), 0, 1e-6) << "length " << len; // ∂L/∂r_b = d̂ [eq. 3.36]
            // The first-order model L(d') ≈ d̂·d' + offset is exact at d' = d.
            EXPECT_NEAR(l.direction.dot(rb - ra) + l.offset, l.length, 1e-15);
            if (len >= eps) {
                EXPECT_NEAR(l.length, len, 1e-15);
                EXPECT_NEAR(l.offset, 0, 1e-15);
                EXPECT_NEAR(l.direction.norm(), 1, 1e-12);
            } else {
                EXPECT_GE(l.length, eps / 2); // smoothed: never zero, so the row never degenerates
                EXPECT_LE(l.direction.norm(), 1 + 1e-12);
            }
        }
    }
}

TEST(ThreadLinearization, ZeroLengthSegmentIsFiniteAndContinuousAtEpsilon) {
    const double eps = 2e-4;
    const ThreadSegmentLinearization z = linearizeThreadSegment(Vec3(1, 2, 3), Vec3(1, 2, 3), eps);
    EXPECT_DOUBLE_EQ(z.length, eps / 2);
    EXPECT_EQ(z.direction, Vec3::Zero());
    const Vec3 a(0, 0, 0);
    const double below = linearizeThreadSegment(a, Vec3(eps * (1 - 1e-9), 0, 0), eps).length;
    const double above = linearizeThreadSegment(a, Vec3(eps * (1 + 1e-9), 0, 0), eps).length;
    EXPECT_NEAR(below, above, 1e-12);
    // Linearized shortening [eq. 3.37]: moving r_b by δ along −d̂ shortens L by |δ| to first order.
    const Vec3 b(0.003, 0.001, -0.002);
    const ThreadSegmentLinearization l = linearizeThreadSegment(a, b, eps);
    const double delta = 1e-6;
    const double shorter = linearizeThreadSegment(a, b - delta * l.direction, eps).length;
    EXPECT_NEAR(l.length - shorter, delta, 1e-12);
}

namespace {

Eigen::Isometry3d randomPose(std::mt19937& rng) {
    std::uniform_real_distribution<double> u(-1, 1);
    Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
    p.linear() = Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized().toRotationMatrix();
    p.translation() = Vec3(u(rng), u(rng), u(rng)) * 0.01;
    return p;
}

} // namespace

TEST(NeedleMotion, SlidingAlongTheCurveIsPureSliding) {
    std::mt19937 rng(5);
    for (auto shape : {NeedleSpec::Shape::Straight, NeedleSpec::Shape::Semicircle}) {
        NeedleSpec spec;
        spec.shape = shape;
        spec.radius = 0.004;
        spec.length = 0.02;
        spec.handle = 0.3 * spec.length_();
        for (int trial = 0; trial < 50; ++trial) {
            const Eigen::Isometry3d p = randomPose(rng);
            for (double sigma : {-2e-3, -1e-4, 0.0, 3e-5, 1e-3, 4e-3}) {
                const Eigen::Isometry3d q = slidePose(spec, p, sigma);
                EXPECT_NEAR(slidingAmount(spec, p, q), sigma, 1e-12) << "shape " << int(shape);
                // The slid curve passes through the same points: point(α) of q is point(α + σ) of p.
                const NeedleCurve a = needleCurve(spec, p), b = needleCurve(spec, q);
                EXPECT_NEAR((b.point(0.5 * spec.length_()) - a.point(0.5 * spec.length_() + sigma)).norm(), 0, 1e-12);
            }
        }
    }
}

TEST(NeedleMotion, MotionNormalToTheCurveIsPureSticking) {
    std::mt19937 rng(6);
    NeedleSpec straight;
    straight.shape = NeedleSpec::Shape::Straight;
    straight.length = 0.02;
    NeedleSpec arc;
    arc.radius = 0.004;
    arc.handle = 0.5 * arc.length_();
    for (int trial = 0; trial < 50; ++trial) {
        const Eigen::Isometry3d p = randomPose(rng);
        // Straight: a translation normal to the axis slides nothing.
        Eigen::Isometry3d q = p;
        const Vec3 w = p.linear().col(0);
        q.translation() += 1e-3 * w.unitOrthogonal();
        EXPECT_NEAR(slidingAmount(straight, p, q), 0, 1e-15);
        // Arc: moving the needle along its plane normal or radially at the handle slides nothing.
        Eigen::Isometry3d r = p;
        r.translation() += 1e-3 * p.linear().col(2);
        EXPECT_NEAR(slidingAmount(arc, p, r), 0, 1e-12);
        const Vec3 handleDir = (needleCurve(arc, p).point(arc.handle) - p.translation()).normalized();
        Eigen::Isometry3d s = p;
        s.translation() += 5e-4 * handleDir;
        EXPECT_NEAR(slidingAmount(arc, p, s), 0, 1e-12);
    }
}
