// Anisotropic strain limiting [A §4.3.4]: gradients, frames, and limits under load.
#include "sim/material/stable_neo_hookean.hpp"
#include "sim/xpbd/strain_limit.hpp"
#include "sim/xpbd/xpbd_solver.hpp"
#include "sim/xpbd/xpbd_system.hpp"
#include "xpbd_test_support.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <limits>

using namespace viscera::sim;
using namespace viscera::sim::testing;
using ::testing::HasSubstr;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

std::array<Vec3, 4> toArray4(const std::vector<Vec3>& x) {
    return {x[0], x[1], x[2], x[3]};
}
std::array<Vec3, 3> toArray3(const std::vector<Vec3>& x) {
    return {x[0], x[1], x[2]};
}

/// Largest and smallest ε_ij over the tets of a body, in material axes.
std::pair<double, double> strainRange(const TetMesh& rest, const std::vector<Vec3>& x, const Mat3& axes, int i, int j) {
    double lo = kInf, hi = -kInf;
    for (const Tet& e : rest.tets()) {
        const auto& X = rest.positions();
        const Mat3 M = tetMaterialDmInv({X[e[0]], X[e[1]], X[e[2]], X[e[3]]}, axes);
        const double eps = tetGreenStrain({x[e[0]], x[e[1]], x[e[2]], x[e[3]]}, M, i, j);
        lo = std::min(lo, eps);
        hi = std::max(hi, eps);
    }
    return {lo, hi};
}

} // namespace

TEST(StrainLimit, TetStrainGradientMatchesFiniteDifferences) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1, 1);
    double worst = 0;
    for (int trial = 0; trial < 40; ++trial) {
        // A random rest tet (positive volume) in random material axes, deformed by a random F
        // plus noise.
        std::vector<Vec3> X = {Vec3::Zero(), Vec3(0.01, 0, 0), Vec3(0, 0.01, 0), Vec3(0, 0, 0.01)};
        for (Vec3& p : X)
            p += 0.003 * Vec3(u(rng), u(rng), u(rng));
        if ((X[1] - X[0]).cross(X[2] - X[0]).dot(X[3] - X[0]) <= 1e-8) continue;
        const Mat3 axes =
            Eigen::Quaterniond(Eigen::Vector4d(u(rng), u(rng), u(rng), u(rng)).normalized()).toRotationMatrix();
        const Mat3 M = tetMaterialDmInv(toArray4(X), axes);
        const Mat3 F = randomF(rng, 0.4);
        std::vector<Vec3> x(4);
        for (int k = 0; k < 4; ++k)
            x[k] = F * X[k] + 1e-3 * Vec3(u(rng), u(rng), u(rng));
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) {
                std::array<Vec3, 4> g;
                tetGreenStrain(toArray4(x), M, i, j, &g);
                const auto f = [&](const std::vector<Vec3>& y) { return tetGreenStrain(toArray4(y), M, i, j); };
                worst = std::max(worst, fdRelativeError(f, x, {g.begin(), g.end()}));
            }
    }
    EXPECT_LT(worst, 1e-6);
}

TEST(StrainLimit, TriangleStrainGradientMatchesFiniteDifferences) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-1, 1);
    double worst = 0;
    for (int trial = 0; trial < 40; ++trial) {
        std::vector<Vec3> X = {Vec3::Zero(), Vec3(0.01, 0, 0), Vec3(0, 0.01, 0)};
        for (Vec3& p : X)
            p += 0.003 * Vec3(u(rng), u(rng), u(rng));
        const std::array<Vec2, 3> uv = {Vec2(u(rng), u(rng)), Vec2(1 + u(rng) * 0.3, u(rng) * 0.3),
                                        Vec2(u(rng) * 0.3, 1 + u(rng) * 0.3)};
        Mat2 M;
        if (!triangleUvDmInv(toArray3(X), uv, M)) continue;
        const Mat3 F = randomF(rng, 0.4);
        std::vector<Vec3> x(3);
        for (int k = 0; k < 3; ++k)
            x[k] = F * X[k] + 1e-3 * Vec3(u(rng), u(rng), u(rng));
        for (int i = 0; i < 2; ++i)
            for (int j = 0; j < 2; ++j) {
                std::array<Vec3, 3> g;
                triGreenStrain(toArray3(x), M, i, j, &g);
                const auto f = [&](const std::vector<Vec3>& y) { return triGreenStrain(toArray3(y), M, i, j); };
                worst = std::max(worst, fdRelativeError(f, x, {g.begin(), g.end()}));
            }
    }
    EXPECT_LT(worst, 1e-6);
}

TEST(StrainLimit, UvFrameFollowsTheTextureDirection) {
    // A triangle in the plane z = 0.01 whose u axis points along t = (1, 1, 0)/√2 and whose uv
    // map is sheared: u = d·t + 0.3 d·b, v = d·b, so ∂x/∂u = t but ∂x/∂v = b − 0.3 t.
    const Vec3 t = Vec3(1, 1, 0).normalized(), b = Vec3(-1, 1, 0).normalized();
    const std::array<Vec3, 3> X = {Vec3(0, 0, 0.01), Vec3(0, 0, 0.01) + 0.02 * t,
                                   Vec3(0, 0, 0.01) + 0.01 * b + 0.005 * t};
    std::array<Vec2, 3> uv;
    for (int k = 0; k < 3; ++k) {
        const Vec3 d = X[k] - X[0];
        uv[k] = Vec2(d.dot(t) + 0.3 * d.dot(b), d.dot(b));
    }
    Mat2 M;
    ASSERT_TRUE(triangleUvDmInv(X, uv, M));
    // Rest: zero strain.
    for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j)
            EXPECT_NEAR(triGreenStrain(X, M, i, j), 0.0, 1e-14);
    // Stretch by s along u: ε_00 = (s² − 1)/2, the rest zero.
    const double s = 1.2;
    std::array<Vec3, 3> x;
    for (int k = 0; k < 3; ++k) {
        const Vec3 d = X[k] - X[0];
        x[k] = X[0] + d + (s - 1) * d.dot(t) * t;
    }
    EXPECT_NEAR(triGreenStrain(x, M, 0, 0), 0.5 * (s * s - 1), 1e-12);
    EXPECT_NEAR(triGreenStrain(x, M, 1, 1), 0.0, 1e-12);
    EXPECT_NEAR(triGreenStrain(x, M, 0, 1), 0.0, 1e-12);
    // Degenerate uv.
    EXPECT_FALSE(triangleUvDmInv(X, {Vec2(0, 0), Vec2(1, 1), Vec2(2, 2)}, M));
}

TEST(StrainLimit, TetMaterialAxesRotateTheStrain) {
    const std::array<Vec3, 4> X = {Vec3::Zero(), Vec3(0.01, 0, 0), Vec3(0, 0.01, 0), Vec3(0, 0, 0.01)};
    const Mat3 axes = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
    const Mat3 M = tetMaterialDmInv(X, axes);
    // Stretch s along material axis 1 (a column of axes).
    const double s = 1.3;
    const Vec3 a = axes.col(1);
    std::array<Vec3, 4> x;
    for (int k = 0; k < 4; ++k)
        x[k] = X[k] + (s - 1) * X[k].dot(a) * a;
    EXPECT_NEAR(tetGreenStrain(x, M, 1, 1), 0.5 * (s * s - 1), 1e-12);
    EXPECT_NEAR(tetGreenStrain(x, M, 0, 0), 0.0, 1e-12);
    EXPECT_NEAR(tetGreenStrain(x, M, 2, 2), 0.0, 1e-12);
    EXPECT_NEAR(tetGreenStrain(x, M, 0, 1), 0.0, 1e-12);
}

namespace {

/// A 9 × 1 × 1 cm bar along x, fixed at x = 0 and pulled at x = L by moving its end nodes; the
/// middle third is 100 times softer (node weights), so the strain gathers there.
struct PulledBar {
    std::unique_ptr<TetMesh> mesh = makeBoxTetMesh({Vec3::Zero(), Vec3(0.09, 0.01, 0.01), {9, 1, 1}});
    std::vector<int32_t> fixed, pulled;
    std::vector<double> weights;

    PulledBar() {
        for (int32_t v = 0; v < static_cast<int32_t>(mesh->vertexCount()); ++v) {
            const double x = mesh->positions()[v].x();
            if (x < 1e-9) fixed.push_back(v);
            if (x > 0.09 - 1e-9) {
                fixed.push_back(v);
                pulled.push_back(v);
            }
            weights.push_back(x > 0.03 - 1e-9 && x < 0.06 + 1e-9 ? 0.01 : 1.0);
        }
    }

    /// Runs the pull to `stretch` × L over 30 frames, then 60 frames of settling.
    std::vector<Vec3> run(std::optional<TetStrainLimits> limits, int iterations = 10) const {
        TetBodyDesc body;
        body.mesh = mesh.get();
        const Material m = tissue(5000);
        body.model = std::make_shared<StableNeoHookeanModel>(m.mu(), m.lambda());
        body.fixedNodes = fixed;
        body.nodeWeights = weights;
        body.strainLimits = std::move(limits);
        XpbdSettings s;
        s.gravity.setZero();
        s.substeps = 20;
        s.iterations = iterations;
        s.damping = 10;
        auto solver = XpbdSolver::create(body, s);
        for (int f = 1; f <= 90; ++f) {
            std::vector<Vec3> x = solver->positions();
            const double stretch = 1.0 + 0.06 * std::min(f, 30) / 30.0;
            for (int32_t v : pulled)
                x[v].x() = 0.09 * stretch;
            solver->setState(x, solver->velocities());
            EXPECT_TRUE(solver->step().finite);
        }
        return solver->positions();
    }
};

} // namespace

TEST(StrainLimit, HardUpperLimitHoldsWhenABlockIsPulled) {
    PulledBar bar;
    const auto free = bar.run(std::nullopt);
    const double unlimited = strainRange(*bar.mesh, free, Mat3::Identity(), 0, 0).second;
    EXPECT_GT(unlimited, 0.15) << "the soft middle should take most of the stretch";
    TetStrainLimits limits;
    limits.limits.push_back({0, 0, -kInf, 0.1, 0.0});
    const auto held = bar.run(limits);
    const double limited = strainRange(*bar.mesh, held, Mat3::Identity(), 0, 0).second;
    EXPECT_LE(limited, 0.1 + 2e-3);
    EXPECT_GT(limited, 0.09) << "the limit is active";
}

TEST(StrainLimit, CompliantLimitYieldsPartially) {
    PulledBar bar;
    TetStrainLimits hard, soft;
    hard.limits.push_back({0, 0, -kInf, 0.1, 0.0});
    soft.limits.push_back({0, 0, -kInf, 0.1, 1.0 / 2e4}); // compliance 1/(20 kPa)
    const double unlimited = strainRange(*bar.mesh, bar.run(std::nullopt), Mat3::Identity(), 0, 0).second;
    const double h = strainRange(*bar.mesh, bar.run(hard), Mat3::Identity(), 0, 0).second;
    const double s = strainRange(*bar.mesh, bar.run(soft), Mat3::Identity(), 0, 0).second;
    EXPECT_GT(s, h + 1e-3);
    EXPECT_LT(s, unlimited - 1e-3);
}

TEST(StrainLimit, RotatedMaterialAxesAndLowerAndBilateralLimits) {
    PulledBar bar;
    // Material axes: axis 2 along world x. An upper limit on ε_22 then limits the pull.
    Mat3 axes;
    axes << 0, 1, 0, 0, 0, 1, 1, 0, 0; // columns: y, z, x
    // Pulling in x contracts y and z (Poisson): a lower limit on ε_00 (world y) keeps it above
    // −0.01, and a bilateral ε_01 = 0 keeps the cross-section unsheared.
    TetStrainLimits limits;
    limits.axes = axes;
    limits.limits.push_back({2, 2, -kInf, 0.1, 0.0});
    limits.limits.push_back({0, 0, -0.01, kInf, 0.0});
    limits.limits.push_back({0, 1, 0.0, 0.0, 0.0});
    const auto free = bar.run(std::nullopt);
    EXPECT_LT(strainRange(*bar.mesh, free, axes, 0, 0).first, -0.02) << "without limits the bar narrows";
    const auto held = bar.run(limits, 20);
    EXPECT_LE(strainRange(*bar.mesh, held, axes, 2, 2).second, 0.1 + 2e-3);
    EXPECT_GE(strainRange(*bar.mesh, held, axes, 0, 0).first, -0.01 - 2e-3);
    const auto shear = strainRange(*bar.mesh, held, axes, 0, 1);
    EXPECT_LT(std::max(-shear.first, shear.second), 2e-3);
}

TEST(StrainLimit, RejectsInvalidLimits) {
    PulledBar bar;
    TetBodyDesc body;
    body.mesh = bar.mesh.get();
    body.model = std::make_shared<StableNeoHookeanModel>(1e3, 1e4);
    body.fixedNodes = bar.fixed;
    auto msg = [&](const TetStrainLimits& l) {
        body.strainLimits = l;
        try {
            XpbdSolver::create(body, XpbdSettings{});
        } catch (const std::invalid_argument& e) {
            return std::string(e.what());
        }
        return std::string("accepted");
    };
    TetStrainLimits l;
    EXPECT_THAT(msg(l), HasSubstr("no limit given"));
    l.limits.push_back({0, 3, -kInf, 0.1, 0.0});
    EXPECT_THAT(msg(l), HasSubstr("strain limit 0: strain entry (0, 3) must be in [0, 2]"));
    l.limits[0] = {0, 0, -kInf, kInf, 0.0};
    EXPECT_THAT(msg(l), HasSubstr("needs a finite lower or upper bound"));
    l.limits[0] = {0, 0, 0.2, 0.1, 0.0};
    EXPECT_THAT(msg(l), HasSubstr("lower must not exceed upper"));
    l.limits[0] = {0, 0, -kInf, 0.1, -1.0};
    EXPECT_THAT(msg(l), HasSubstr("compliance must be finite and >= 0"));
    l.limits[0] = {0, 0, -kInf, 0.1, 0.0};
    l.axes = Mat3::Identity() * 2;
    EXPECT_THAT(msg(l), HasSubstr("material axes must be orthonormal"));
    l.axes = Mat3::Identity();
    l.tets = {99999};
    EXPECT_THAT(msg(l), HasSubstr("tet 99999 is out of range"));
    l.tets = {0, 1};
    EXPECT_EQ(msg(l), "accepted");
}
