#include "step_problems.hpp"

#include "sim/reference/accuracy.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

using namespace viscera::sim;
using namespace viscera::sim::testing;
using ::testing::HasSubstr;

namespace {

/// x_k = x* + 2^-k (x_0 − x*): a synthetic iterate stream converging linearly to x*.
std::vector<Vec3> towards(const std::vector<Vec3>& x0, const std::vector<Vec3>& xStar, int k) {
    std::vector<Vec3> x(x0.size());
    const double s = std::ldexp(1.0, -k);
    for (size_t i = 0; i < x.size(); ++i)
        x[i] = xStar[i] + s * (x0[i] - xStar[i]);
    return x;
}

} // namespace

TEST(RelativeError, IsOneAtTheStartZeroAtTheSolutionAndAffineInvariant) {
    EXPECT_EQ(relativeError(5.0, 5.0, 2.0), 1.0);
    EXPECT_EQ(relativeError(2.0, 5.0, 2.0), 0.0);
    EXPECT_NEAR(relativeError(2.3, 5.0, 2.0), 0.1, 1e-15);
    // f(x_0) = f(x*): nothing to converge, reported as 0.
    EXPECT_EQ(relativeError(3.0, 2.0, 2.0), 0.0);
    // Invariant under f → a f + b (a > 0): units and the energy's constant do not matter.
    for (double a : {1e-9, 1.0, 1e6})
        for (double b : {-1e3 * a, 0.0, 7.0 * a})
            EXPECT_NEAR(relativeError(a * 2.3 + b, a * 5.0 + b, a * 2.0 + b), 0.1, 1e-12);
    // Monotone in f(x_k); negative below the reference (a reference that is not converged).
    EXPECT_LT(relativeError(2.2, 5.0, 2.0), relativeError(2.4, 5.0, 2.0));
    EXPECT_LT(relativeError(1.9, 5.0, 2.0), 0.0);
}

TEST(AccuracyRecorder, StartsAtOneAndReachesZeroAtTheReference) {
    const StepProblem p = makeBlockProblem({});
    const NewtonResult ref = solveNewton(p, p.xTilde);
    ASSERT_TRUE(ref.converged());
    AccuracyRecorder rec("synthetic", p, ref, p.xTilde);
    rec.observe(0, p.xTilde, 0.0); // ignored: x_0 is recorded at construction
    for (int k = 1; k <= 20; ++k)
        rec.observe(k, towards(p.xTilde, ref.x, k), 1e-3 * k);
    rec.observe(21, ref.x, 0.021);
    const AccuracyTrace& t = rec.trace();
    EXPECT_EQ(t.solver, "synthetic");
    ASSERT_EQ(t.iterations.size(), 22u);
    ASSERT_EQ(t.relError.size(), 22u);
    ASSERT_EQ(t.timeMs.size(), 22u);
    EXPECT_EQ(t.iterations.front(), 0);
    EXPECT_EQ(t.iterations.back(), 21);
    EXPECT_EQ(t.relError.front(), 1.0);
    EXPECT_EQ(t.relError.back(), 0.0);
    EXPECT_EQ(t.timeMs.front(), 0.0);
    EXPECT_DOUBLE_EQ(t.timeMs[10], 10.0);
    EXPECT_EQ(t.f0, p.objective(p.xTilde));
    EXPECT_EQ(t.fStar, ref.f);
    EXPECT_EQ(t.h, p.h);
    EXPECT_EQ(t.referenceStatus, "converged");
    EXPECT_EQ(t.referenceIterations, ref.iterations);
    EXPECT_EQ(t.referenceGradientNorm, ref.gradientNorms.back());
    EXPECT_GT(t.referenceMs, 0.0);
    // Near x*, f − f* is quadratic in the distance: halving the distance quarters the error.
    for (size_t k = 1; k < t.relError.size(); ++k)
        EXPECT_LT(t.relError[k], t.relError[k - 1]);
    EXPECT_NEAR(t.relError[12] / t.relError[11], 0.25, 0.01);
    EXPECT_EQ(firstBelow(t, 1e-4), 7); // 4^-k first below 1e-4 at k = 7
    EXPECT_EQ(firstBelow(t, 1.0), 0);
    EXPECT_EQ(firstBelow(t, -1.0), -1);
}

TEST(AccuracyRecorder, RejectsOutOfOrderIterationsAndWrongSizes) {
    const StepProblem p = makeBlockProblem({});
    const NewtonResult ref = solveNewton(p, p.xTilde);
    EXPECT_THROW(AccuracyRecorder("x", p, ref, {Vec3::Zero()}), std::invalid_argument);
    AccuracyRecorder rec("x", p, ref, p.xTilde);
    rec.observe(2, p.xTilde, 0.0);
    try {
        rec.observe(2, p.xTilde, 0.0);
        FAIL() << "no exception";
    } catch (const std::invalid_argument& e) {
        EXPECT_STREQ(e.what(), "sim::AccuracyRecorder::observe(): iteration 2 does not follow 2");
    }
    try {
        rec.observe(3, {Vec3::Zero()}, 0.0);
        FAIL() << "no exception";
    } catch (const std::invalid_argument& e) {
        EXPECT_THAT(e.what(), HasSubstr("x_k has 1 nodes, the problem has"));
    }
}

TEST(MeasureNewton, TraceFallsFromOneToZeroOverNewtonsOwnIterations) {
    BlockSpec s;
    s.youngsModulus = 3000;
    const StepProblem p = makeBlockProblem(s);
    const AccuracyTrace t = measureNewton(p);
    EXPECT_EQ(t.solver, "newton");
    EXPECT_EQ(t.referenceStatus, "converged");
    ASSERT_EQ(t.relError.size(), static_cast<size_t>(t.referenceIterations) + 1);
    EXPECT_EQ(t.relError.front(), 1.0);
    EXPECT_EQ(t.relError.back(), 0.0);
    EXPECT_LT(t.fStar, t.f0);
    for (size_t k = 1; k < t.relError.size(); ++k) {
        EXPECT_EQ(t.iterations[k], static_cast<int>(k));
        EXPECT_LE(t.relError[k], t.relError[k - 1] + t.relErrorFloor); // noise once converged
        EXPECT_GE(t.timeMs[k], t.timeMs[k - 1]);
    }
    // Newton's first step already removes most of the error (Fig. 4.12 a).
    EXPECT_LT(t.relError[1], 1e-2);
    EXPECT_GE(t.referenceMs, t.timeMs.back());
}
