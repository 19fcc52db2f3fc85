// Exp-map rotation update [A eq. 5.17–5.18] against Rodrigues/AngleAxis and the polar
// decomposition (JacobiSVD).
#include "sim/clip/exp_map_rotation.hpp"

#include <Eigen/SVD>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>

using namespace viscera::sim;

namespace {

Mat3 randomRotation(std::mt19937& rng, double maxAngle) {
    std::normal_distribution<double> n(0, 1);
    std::uniform_real_distribution<double> u(0, maxAngle);
    Vec3 axis(n(rng), n(rng), n(rng));
    return Eigen::AngleAxisd(u(rng), axis.normalized()).toRotationMatrix();
}

Mat3 randomSpd(std::mt19937& rng) {
    std::uniform_real_distribution<double> u(0.5, 1.8);
    const Mat3 V = randomRotation(rng, std::numbers::pi);
    return V * Vec3(u(rng), u(rng), u(rng)).asDiagonal() * V.transpose();
}

} // namespace

TEST(ExpMapRotation, RodriguesMatchesAngleAxis) {
    std::mt19937 rng(3);
    std::normal_distribution<double> n(0, 1);
    for (double angle : {0.0, 1e-12, 1e-9, 1e-5, 1e-4, 0.3, 1.0, 2.5, std::numbers::pi - 1e-9, std::numbers::pi}) {
        for (int k = 0; k < 5; ++k) {
            const Vec3 axis = Vec3(n(rng), n(rng), n(rng)).normalized();
            const Mat3 R = expMapRotation(angle * axis);
            const Mat3 ref = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
            EXPECT_LT((R - ref).cwiseAbs().maxCoeff(), 1e-15 + 1e-14 * angle) << angle;
            EXPECT_LT((R.transpose() * R - Mat3::Identity()).cwiseAbs().maxCoeff(), 1e-14);
            EXPECT_NEAR(R.determinant(), 1.0, 1e-14);
        }
    }
    EXPECT_EQ(expMapRotation(Vec3::Zero()), Mat3::Identity());
}

TEST(ExpMapRotation, IncrementIsZeroAtThePolarRotationAndFollowsEq518) {
    std::mt19937 rng(5);
    const Mat3 R = randomRotation(rng, 2.0), S = randomSpd(rng);
    const Mat3 A = R * S;
    EXPECT_LT(expMapIncrement(A, R).norm(), 1e-12);
    // Direct evaluation of eq. 5.18 at another estimate.
    const Mat3 R1 = randomRotation(rng, 2.0);
    Vec3 num = Vec3::Zero();
    double den = 0;
    for (int k = 0; k < 3; ++k) {
        num += R1.col(k).cross(A.col(k));
        den += R1.col(k).dot(A.col(k));
    }
    EXPECT_LT((expMapIncrement(A, R1, 1e-9) - num / (std::abs(den) + 1e-9)).norm(), 1e-15);
}

TEST(ExpMapRotation, ConvergesToPolarRotationOnStaticA) {
    std::mt19937 rng(11);
    double worst = 0;
    int worstIterations = 0;
    for (int trial = 0; trial < 200; ++trial) {
        const Mat3 Rtrue = randomRotation(rng, 0.95 * std::numbers::pi);
        const Mat3 A = Rtrue * randomSpd(rng);
        const Mat3 polar = polarRotation(A);
        ASSERT_LT(rotationAngleBetween(polar, Rtrue), 1e-9);
        // Cold start from identity (large rotations), or warm start from a nearby estimate.
        Mat3 R = trial % 2 ? Mat3::Identity() : Mat3(Rtrue * randomRotation(rng, 0.5));
        const int it = refineRotationExpMap(A, R, {200, 1e-9, 1e-14});
        ASSERT_GE(it, 0);
        worstIterations = std::max(worstIterations, it);
        const double err = rotationAngleBetween(R, polar);
        worst = std::max(worst, err);
        EXPECT_LT(err, 1e-6) << "trial " << trial << " after " << it << " iterations";
        EXPECT_LT((R.transpose() * R - Mat3::Identity()).cwiseAbs().maxCoeff(), 1e-12);
        EXPECT_NEAR(R.determinant(), 1.0, 1e-12);
    }
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g", worst);
    RecordProperty("worst_angle_rad", buf);
    RecordProperty("worst_iterations", worstIterations);
}

TEST(ExpMapRotation, FewIterationsPerFrameTrackASlowRotation) {
    // A turning by δ = 2° per frame with a fixed stretch S. Linearising eq. 5.17–5.18 about the
    // polar rotation, one iteration multiplies the error about S's k-th axis by s_k / tr S, so
    // after n warm-started iterations per frame the lag is at most δ ρⁿ / (1 − ρⁿ),
    // ρ = max s_k / tr S (here 1.3 / 3.15).
    const Vec3 s(1.3, 0.8, 1.05);
    const Mat3 S = s.asDiagonal();
    const double delta = std::numbers::pi / 90, rho = s.maxCoeff() / s.sum();
    for (int n : {2, 4, 8, 12}) {
        Mat3 R = Mat3::Identity();
        double worst = 0;
        for (int f = 1; f <= 180; ++f) {
            const Mat3 Rt = Eigen::AngleAxisd(f * delta, Vec3(1, 2, 3).normalized()).toRotationMatrix();
            const Mat3 A = Rt * S;
            refineRotationExpMap(A, R, {n, 1e-9, 0});
            if (f > 20) worst = std::max(worst, rotationAngleBetween(R, polarRotation(A)));
        }
        const double bound = delta * std::pow(rho, n) / (1 - std::pow(rho, n));
        EXPECT_LT(worst, 1.05 * bound) << n;
        EXPECT_GT(worst, 0.05 * bound) << n;
        if (n == 12) {
            EXPECT_LT(worst, 1e-6);
        }
    }
}

TEST(ExpMapRotation, SingularAndNonFiniteA) {
    // Rank 2: the rotation is still determined by the two informative columns.
    const Mat3 Rt = Eigen::AngleAxisd(1.1, Vec3(0.3, -1, 0.2).normalized()).toRotationMatrix();
    const Mat3 A = Rt * Vec3(1.2, 0.9, 0.0).asDiagonal();
    Mat3 R = Mat3::Identity();
    refineRotationExpMap(A, R, {100, 1e-9, 0});
    EXPECT_LT(rotationAngleBetween(R, Rt), 1e-8);
    EXPECT_LT(rotationAngleBetween(polarRotation(A), Rt), 1e-12);
    // Zero A: ω = 0, R stays.
    Mat3 R2 = Rt;
    refineRotationExpMap(Mat3::Zero(), R2, {10, 1e-9, 0});
    EXPECT_TRUE(R2.allFinite());
    EXPECT_LT(rotationAngleBetween(R2, Rt), 1e-12);
    // Non-finite A: refused, R untouched.
    Mat3 B = A;
    B(1, 2) = std::numeric_limits<double>::quiet_NaN();
    Mat3 R3 = Rt;
    EXPECT_EQ(refineRotationExpMap(B, R3), -1);
    EXPECT_EQ(R3, Rt);
    EXPECT_THROW(polarRotation(B), std::invalid_argument);
    // A reflection: the closest rotation (flip through the smallest singular direction).
    const Mat3 Refl = Vec3(2.0, 1.5, -0.5).asDiagonal();
    EXPECT_LT((polarRotation(Refl) - Mat3(Vec3(1, 1, 1).asDiagonal())).norm(), 1e-12);
}

TEST(ExpMapRotation, AngleBetweenIsAccurateAtBothEnds) {
    const Mat3 I = Mat3::Identity();
    for (double a : {1e-9, 1e-5, 0.7, 3.0, std::numbers::pi - 1e-7, std::numbers::pi})
        EXPECT_NEAR(rotationAngleBetween(I, Eigen::AngleAxisd(a, Vec3::UnitZ()).toRotationMatrix()), a,
                    1e-12 + 1e-9 * a)
            << a;
}
