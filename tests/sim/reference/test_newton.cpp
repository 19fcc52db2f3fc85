#include "step_problems.hpp"

#include "sim/reference/newton.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>

#include <Eigen/Geometry>

#include <cmath>
#include <limits>

using namespace viscera::sim;
using namespace viscera::sim::testing;
using ::testing::HasSubstr;

namespace {

/// The free end pushed sideways and down by up to 3 cm: a step with large, nonlinear strain.
StepProblem bentBlock() {
    BlockSpec s;
    s.youngsModulus = 3000;
    StepProblem p = makeBlockProblem(s);
    for (size_t i = 0; i < p.xTilde.size(); ++i)
        if (!p.fixed[i]) p.xTilde[i] += Vec3(0, 0.01, -0.03) * (p.xTilde[i].x() / 0.08);
    return p;
}

/// A long step (h = 0.1 s) of a light block: elasticity dominates inertia.
StepProblem stiffStep() {
    BlockSpec s;
    s.h = 0.1;
    s.density = 100;
    return makeBlockProblem(s);
}

/// Free nodes squashed to 30 % along x (and optionally mirrored in z: every tet inverted).
std::vector<Vec3> squashed(const StepProblem& p, bool invert) {
    std::vector<Vec3> x = p.xTilde;
    for (Vec3& v : x) {
        v.x() *= 0.3;
        if (invert) v.z() *= -1;
    }
    return x;
}

std::vector<Vec3> jittered(std::vector<Vec3> x, const StepProblem& p, double amplitude) {
    uint32_t state = 12345;
    auto next = [&] {
        state = state * 1664525u + 1013904223u;
        return (state >> 8) / double(1u << 24) * 2.0 - 1.0;
    };
    for (size_t i = 0; i < x.size(); ++i)
        if (!p.fixed[i]) x[i] += amplitude * Vec3(next(), next(), next());
    return x;
}

NewtonSettings exactWhenDefinite() {
    NewtonSettings s;
    s.hessian = NewtonHessian::ExactWhenDefinite;
    return s;
}

void expectConsistentRecord(const NewtonResult& r) {
    ASSERT_EQ(r.objectives.size(), static_cast<size_t>(r.iterations) + 1);
    ASSERT_EQ(r.gradientNorms.size(), r.objectives.size());
    ASSERT_EQ(r.seconds.size(), r.objectives.size());
    for (size_t k = 1; k < r.seconds.size(); ++k)
        EXPECT_GE(r.seconds[k], r.seconds[k - 1]);
    EXPECT_GE(r.totalSeconds, r.seconds.back());
    EXPECT_EQ(r.f, r.objectives.back());
}

} // namespace

TEST(Newton, ConvergesInFewIterationsOnAGravityBlock) {
    const StepProblem p = makeBlockProblem({});
    const NewtonResult r = solveNewton(p, p.xTilde);
    ASSERT_EQ(r.status, NewtonStatus::Converged) << r.message;
    EXPECT_TRUE(r.message.empty());
    expectConsistentRecord(r);
    EXPECT_LE(r.iterations, 6);
    EXPECT_EQ(r.projectedSteps, r.iterations);
    EXPECT_LE(r.gradientNorms.back(), 1e-11 * std::max(1.0, r.gradientNorms.front()));
    for (size_t k = 1; k < r.gradientNorms.size(); ++k)
        EXPECT_LT(r.gradientNorms[k], r.gradientNorms[k - 1]);
    // Projected Newton: at least ×10 per iteration in the tail (measured ×30; the projection of
    // the element Hessians that are indefinite at x* keeps it from being quadratic).
    const size_t n = r.gradientNorms.size();
    EXPECT_LT(r.gradientNorms[n - 1], 0.1 * r.gradientNorms[n - 2]);
}

TEST(Newton, ACancelFlagEndsTheSolveBeforeItsNextIteration) {
    // A preview that stops does not wait for a converged reference: set before the solve, no step
    // is taken; clear, the same solve converges.
    const StepProblem p = makeBlockProblem({});
    std::atomic<bool> cancel{true};
    NewtonSettings s;
    s.cancel = &cancel;
    const NewtonResult stopped = solveNewton(p, p.xTilde, s);
    EXPECT_EQ(stopped.status, NewtonStatus::Cancelled);
    EXPECT_EQ(stopped.iterations, 0);
    EXPECT_STREQ(newtonStatusName(stopped.status), "cancelled");
    EXPECT_EQ(stopped.message, "cancelled at iteration 0");
    cancel = false;
    EXPECT_EQ(solveNewton(p, p.xTilde, s).status, NewtonStatus::Converged);
}

TEST(Newton, ExactHessianWhenDefiniteConvergesQuadratically) {
    const StepProblem p = makeBlockProblem({});
    const NewtonResult r = solveNewton(p, p.xTilde, exactWhenDefinite());
    ASSERT_EQ(r.status, NewtonStatus::Converged) << r.message;
    expectConsistentRecord(r);
    EXPECT_LE(r.iterations, 4);
    EXPECT_EQ(r.projectedSteps, 0);
    // Each iteration reduces the gradient by a larger factor than the one before (measured:
    // ×5, ×290, ×4700), the signature of quadratic convergence.
    const auto& g = r.gradientNorms;
    ASSERT_GE(g.size(), 4u);
    for (size_t k = 2; k < g.size(); ++k)
        EXPECT_LT(g[k] / g[k - 1], 0.5 * g[k - 1] / g[k - 2]) << "k = " << k;
}

TEST(Newton, GradientVanishesAtTheSolution) {
    for (const StepProblem& p : {makeBlockProblem({}), bentBlock(), stiffStep()}) {
        const NewtonResult r = solveNewton(p, p.xTilde);
        ASSERT_TRUE(r.converged()) << r.message;
        const double g0 = gradientInfNorm(p, p.xTilde);
        const double gStar = gradientInfNorm(p, r.x);
        EXPECT_LE(gStar, 1e-11 * std::max(1.0, g0));
        EXPECT_LE(gStar, 1e-5 * g0);
        EXPECT_EQ(gStar, r.gradientNorms.back());
        EXPECT_LT(r.f, p.objective(p.xTilde));
    }
}

TEST(Newton, SolutionDoesNotDependOnTheStartingPoint) {
    for (const StepProblem& p : {makeBlockProblem({}), bentBlock(), stiffStep()}) {
        const NewtonResult a = solveNewton(p, p.xTilde);
        ASSERT_TRUE(a.converged()) << a.message;
        const std::vector<std::vector<Vec3>> starts = {restPositions({}), jittered(p.xTilde, p, 2e-3),
                                                       squashed(p, false), squashed(p, true)};
        for (size_t i = 0; i < starts.size(); ++i) {
            for (const NewtonSettings& s : {NewtonSettings{}, exactWhenDefinite()}) {
                const NewtonResult b = solveNewton(p, starts[i], s);
                ASSERT_TRUE(b.converged()) << "start " << i << ": " << b.message;
                EXPECT_LT(maxDistance(a.x, b.x), 1e-8) << "start " << i; // block is 8 cm long
                EXPECT_NEAR(a.f, b.f, 1e-12 * std::abs(a.f)) << "start " << i;
            }
        }
    }
}

TEST(Newton, ObjectiveDecreasesMonotonically) {
    const StepProblem p = stiffStep();
    for (bool invert : {false, true})
        for (const NewtonSettings& s : {NewtonSettings{}, exactWhenDefinite()}) {
            const NewtonResult r = solveNewton(p, squashed(p, invert), s);
            ASSERT_TRUE(r.converged()) << r.message;
            EXPECT_GT(r.iterations, 5); // a hard start: the line search is exercised
            // Strict Armijo decrease, except in the rounding-noise tail where f can no longer
            // rank two points (accepted there only when the gradient still shrinks).
            const double noise = 64 * std::numeric_limits<double>::epsilon() * std::abs(r.f);
            for (size_t k = 1; k < r.objectives.size(); ++k)
                EXPECT_LE(r.objectives[k], r.objectives[k - 1] + noise) << "k = " << k;
        }
}

TEST(Newton, ExactHessianFallsBackToProjectionWhereIndefinite) {
    const StepProblem p = stiffStep();
    const NewtonResult projected = solveNewton(p, squashed(p, true));
    const NewtonResult mixed = solveNewton(p, squashed(p, true), exactWhenDefinite());
    ASSERT_TRUE(projected.converged()) << projected.message;
    ASSERT_TRUE(mixed.converged()) << mixed.message;
    EXPECT_GT(mixed.projectedSteps, 0);
    EXPECT_LT(mixed.projectedSteps, mixed.iterations);
    EXPECT_LT(maxDistance(projected.x, mixed.x), 1e-8);
}

TEST(Newton, FixedNodesStayAtTheirPrescribedPositions) {
    const StepProblem p = bentBlock();
    std::vector<Vec3> x0 = p.xTilde;
    size_t fixedCount = 0;
    for (size_t i = 0; i < x0.size(); ++i)
        if (p.fixed[i]) {
            x0[i] += Vec3(0.01, -0.02, 0.005); // a wrong start for a fixed node is corrected
            ++fixedCount;
        }
    ASSERT_GT(fixedCount, 0u);
    for (const NewtonSettings& s : {NewtonSettings{}, exactWhenDefinite()}) {
        const NewtonResult r = solveNewton(p, x0, s);
        ASSERT_TRUE(r.converged()) << r.message;
        for (size_t i = 0; i < x0.size(); ++i)
            if (p.fixed[i]) {
                EXPECT_EQ(r.x[i], p.xTilde[i]) << "node " << i;
            }
    }
}

TEST(Newton, ZeroLoadReturnsToRest) {
    BlockSpec s;
    s.gravity.setZero();
    const StepProblem p = makeBlockProblem(s);
    const std::vector<Vec3> rest = restPositions(s);
    ASSERT_EQ(p.xTilde, rest);
    // Already at the solution: ∇f is rounding noise; converged without moving.
    const NewtonResult atRest = solveNewton(p, rest);
    ASSERT_TRUE(atRest.converged()) << atRest.message;
    EXPECT_LE(atRest.iterations, 3);
    EXPECT_LT(maxDistance(atRest.x, rest), 1e-15);
    // From a perturbed start it comes back to rest.
    const NewtonResult r = solveNewton(p, jittered(rest, p, 1e-3));
    ASSERT_TRUE(r.converged()) << r.message;
    EXPECT_LT(maxDistance(r.x, rest), 1e-9);
    EXPECT_NEAR(r.f, p.objective(rest), 1e-13 * p.objective(rest));
}

TEST(Newton, UnconstrainedBodyFallsAsARigidTranslation) {
    BlockSpec s;
    s.fixedBelowX = -1; // no fixed node
    const StepProblem p = makeBlockProblem(s);
    // x̃ = rest + h² g is a translation: zero strain and zero inertia residual, so x* = x̃.
    const NewtonResult r = solveNewton(p, restPositions(s));
    ASSERT_TRUE(r.converged()) << r.message;
    EXPECT_LT(maxDistance(r.x, p.xTilde), 1e-9);
}

TEST(Newton, RigidRotationIsAnExactSolution) {
    BlockSpec s;
    s.fixedBelowX = -1;
    s.gravity.setZero();
    StepProblem p = makeBlockProblem(s);
    const Eigen::Matrix3d R = Eigen::AngleAxisd(0.4, Vec3(1, 2, 3).normalized()).toRotationMatrix();
    const Vec3 c(0.04, 0.01, 0.01);
    for (Vec3& v : p.xTilde)
        v = c + R * (v - c);
    // Stable Neo-Hookean is rotation invariant: the rotated block is unstrained.
    const NewtonResult r = solveNewton(p, restPositions(s));
    ASSERT_TRUE(r.converged()) << r.message;
    EXPECT_LT(maxDistance(r.x, p.xTilde), 1e-9);
}

TEST(Newton, StopsAtTheIterationLimitWithAStatus) {
    const StepProblem p = bentBlock();
    NewtonSettings s;
    s.maxIterations = 1;
    const NewtonResult r = solveNewton(p, p.xTilde, s);
    EXPECT_EQ(r.status, NewtonStatus::MaxIterations);
    EXPECT_STREQ(newtonStatusName(r.status), "max_iterations");
    EXPECT_EQ(r.iterations, 1);
    EXPECT_THAT(r.message, HasSubstr("no convergence in 1 iterations"));
    expectConsistentRecord(r);
    EXPECT_LT(r.f, r.objectives.front());
}

TEST(Newton, ReportsASingularHessianAsAStatus) {
    StepProblem p = makeBlockProblem({});
    // A free node with no mass whose tets carry no stiffness: its rows of H are zero.
    size_t node = 0;
    while (p.fixed[node])
        ++node;
    p.mass[node] = 0;
    for (size_t t = 0; t < p.tets.size(); ++t)
        for (int32_t v : p.tets[t])
            if (static_cast<size_t>(v) == node) p.weight[t] = 0;
    NewtonResult r;
    EXPECT_NO_THROW(r = solveNewton(p, p.xTilde));
    EXPECT_EQ(r.status, NewtonStatus::FactorizationFailed);
    EXPECT_STREQ(newtonStatusName(r.status), "factorization_failed");
    EXPECT_THAT(r.message, HasSubstr("not positive definite"));
    EXPECT_EQ(r.x.size(), p.xTilde.size());
}

TEST(Newton, ReportsANonFiniteStartAsAStatus) {
    const StepProblem p = makeBlockProblem({});
    std::vector<Vec3> x0 = p.xTilde;
    x0.back().y() = std::numeric_limits<double>::quiet_NaN();
    NewtonResult r;
    EXPECT_NO_THROW(r = solveNewton(p, x0));
    EXPECT_EQ(r.status, NewtonStatus::NonFinite);
    EXPECT_THAT(r.message, HasSubstr("non-finite"));
}

TEST(Newton, RejectsInconsistentInputWithAMessage) {
    const StepProblem p = makeBlockProblem({});
    auto message = [&](const StepProblem& q, const std::vector<Vec3>& x0, const NewtonSettings& s) {
        try {
            solveNewton(q, x0, s);
        } catch (const std::invalid_argument& e) {
            return std::string(e.what());
        }
        return std::string("no exception");
    };
    NewtonSettings bad;
    bad.armijo = 2;
    EXPECT_EQ(message(p, p.xTilde, bad), "sim::solveNewton(): armijo 2 must be in (0, 1)");
    bad = {};
    bad.tolerance = 0;
    EXPECT_EQ(message(p, p.xTilde, bad), "sim::solveNewton(): tolerance 0 must be positive");
    EXPECT_EQ(message(p, {Vec3::Zero()}, {}),
              "sim::solveNewton(): x0 has 1 nodes, the problem has " + std::to_string(p.xTilde.size()));
    StepProblem q = p;
    q.model.reset();
    EXPECT_EQ(message(q, p.xTilde, {}), "sim::solveNewton(): problem has no constraint model");
    q = p;
    q.tets[3][2] = 9999;
    EXPECT_THAT(message(q, p.xTilde, {}), HasSubstr("tet 3 references node 9999"));
    q = p;
    q.volume[5] = -1e-9;
    EXPECT_THAT(message(q, p.xTilde, {}), HasSubstr("tet 5 has rest volume -1e-09 m^3"));
}
