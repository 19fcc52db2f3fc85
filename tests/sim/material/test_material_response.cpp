#include "material_test_support.hpp"

#include "sim/material/editable_curves.hpp"
#include "sim/material/laws.hpp"
#include "sim/material/material_response.hpp"
#include "sim/util/error.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <limits>

using namespace viscera::sim;
using namespace viscera::sim::testing;
using ::testing::HasSubstr;

namespace {

/// Analytic compressible Neo-Hookean uniaxial state, solved independently in long double:
/// F = diag(λ, t, t), J = λt², P22 = μ(t − 1/t) + λ_L log J / t = 0 ⇔ μ(t² − 1) + λ_L log(λt²) = 0
/// (strictly increasing in t), by bisection to the last bit; P11 = μ(λ − 1/λ) + λ_L log J / λ.
struct NhUniaxial {
    long double t, p11;
};
NhUniaxial nhUniaxial(double stretch, double mu, double lambda) {
    const long double l = stretch, m = mu, L = lambda;
    const auto f = [&](long double t) { return m * (t * t - 1) + L * std::log(l * t * t); };
    long double a = 1e-4L, b = 1e4L;
    for (int i = 0; i < 200 && b - a > 0; ++i) {
        const long double c = 0.5L * (a + b);
        if (c == a || c == b) break;
        (f(c) < 0 ? a : b) = c;
    }
    const long double t = 0.5L * (a + b);
    return {t, m * (l - 1 / l) + L * std::log(l * t * t) / l};
}

/// Test density whose lateral stress never vanishes: Ψ = c (tr F − 3), P = c I.
class ConstantStressDensity final : public EnergyDensity {
public:
    explicit ConstantStressDensity(double c) : m_c(c) {}
    std::string name() const override { return "constant_stress"; }
    double psi(const Mat3& F) const override { return m_c * (F.trace() - 3.0); }
    Mat3 stress(const Mat3&) const override { return m_c * Mat3::Identity(); }
    double restStiffness() const override { return 1.0; }

private:
    double m_c;
};

/// A density whose stress is NaN.
class NanDensity final : public EnergyDensity {
public:
    std::string name() const override { return "nan"; }
    double psi(const Mat3&) const override { return std::numeric_limits<double>::quiet_NaN(); }
    Mat3 stress(const Mat3&) const override { return Mat3::Constant(std::numeric_limits<double>::quiet_NaN()); }
    double restStiffness() const override { return 1.0; }
};

std::vector<double> stretches(double lo, double hi, int n) {
    std::vector<double> out;
    for (int i = 0; i < n; ++i)
        out.push_back(lo + (hi - lo) * i / (n - 1));
    return out;
}

} // namespace

TEST(MaterialResponse, UniaxialMatchesAnalyticNeoHookean) {
    // Acceptance: the analytic law (laws.hpp) and its dense Valanis–Landel form over the Lamé
    // sweep, stretch 0.3–3, against the independent long-double solve.
    double worstAnalytic = 0, worstCurves = 0;
    for (const Lame& p : lameSweep()) {
        const NeoHookeanDensity nh(p.mu, p.lambda);
        const ValanisLandelDensity vl("nh", neoHookeanCurves(p.mu, p.lambda));
        for (double s : stretches(0.3, 3.0, 55)) {
            if (std::abs(s - 1.0) < 1e-12) continue;
            const NhUniaxial ref = nhUniaxial(s, p.mu, p.lambda);
            const double scale = std::abs(static_cast<double>(ref.p11));
            const UniaxialResponse a = uniaxialNominalStress(nh, s);
            ASSERT_TRUE(a.solved);
            EXPECT_EQ(a.stretch, s);
            const double ea = std::abs(a.nominalStress - static_cast<double>(ref.p11)) / scale;
            EXPECT_LT(ea, 1e-8) << "E=" << p.youngs << " nu=" << p.poisson << " stretch " << s;
            EXPECT_NEAR(a.lateralStretch, static_cast<double>(ref.t), 1e-10);
            EXPECT_LT(std::abs(a.lateralStress), 1e-9 * (p.lambda + 2 * p.mu));
            worstAnalytic = std::max(worstAnalytic, ea);
            const UniaxialResponse v = uniaxialNominalStress(vl, s);
            ASSERT_TRUE(v.solved);
            const double ev = std::abs(v.nominalStress - static_cast<double>(ref.p11)) / scale;
            EXPECT_LT(ev, 1e-6) << "E=" << p.youngs << " nu=" << p.poisson << " stretch " << s;
            worstCurves = std::max(worstCurves, ev);
        }
    }
    RecordProperty("uniaxial_nh_analytic_max_rel_error", sci(worstAnalytic));
    RecordProperty("uniaxial_nh_dense_curves_max_rel_error", sci(worstCurves));
}

TEST(MaterialResponse, UniaxialStressIsTheDerivativeOfTheEnergyAlongTheTest) {
    // Along the uniaxial path W(λ) = Ψ(diag(λ, t(λ), t(λ))) and ∂Ψ/∂t = 2 P22 = 0, so
    // dW/dλ = P11: 4th-order central differences of Ψ, every density, stretch 0.6–1.6.
    for (const auto& [label, density, invariant] : allDensities(1e3, 1e4)) {
        double worst = 0;
        for (double s : stretches(0.6, 1.6, 21)) {
            const UniaxialResponse u = uniaxialNominalStress(*density, s);
            ASSERT_TRUE(u.solved) << label << " stretch " << s;
            const auto W = [&](double l) {
                const UniaxialResponse v = uniaxialNominalStress(*density, l);
                return density->psi(Eigen::Vector3d(l, v.lateralStretch, v.lateralStretch).asDiagonal());
            };
            const double h = 1e-4;
            const double fd = (-W(s + 2 * h) + 8 * W(s + h) - 8 * W(s - h) + W(s - 2 * h)) / (12 * h);
            // The lateral face is free: the Ψ-gradient there vanishes.
            const Mat3 F = Eigen::Vector3d(s, u.lateralStretch, u.lateralStretch).asDiagonal();
            const Mat3 g = centralDifference([&](const Mat3& G) { return density->psi(G); }, F);
            const double scale = 1e4 + 2e3;
            EXPECT_LT(std::abs(g(1, 1)), 1e-6 * scale) << label << " stretch " << s;
            EXPECT_LT(std::abs(g(2, 2)), 1e-6 * scale) << label << " stretch " << s;
            EXPECT_NEAR(g(0, 0), u.nominalStress, 1e-6 * scale) << label << " stretch " << s;
            const double e = std::abs(fd - u.nominalStress) / std::max(std::abs(u.nominalStress), 1e-3 * scale);
            EXPECT_LT(e, 1e-6) << label << " stretch " << s;
            worst = std::max(worst, e);
        }
        RecordProperty("uniaxial_dW_dlambda_max_rel_" + label, sci(worst));
    }
}

TEST(MaterialResponse, SimpleShearIsTheDerivativeOfTheEnergy) {
    for (const auto& [label, density, invariant] : allDensities(1e3, 1e4)) {
        for (double gamma : {0.0, 0.05, 0.3, 0.8, 1.5}) {
            const ShearResponse r = simpleShearStress(*density, gamma);
            EXPECT_EQ(r.shear, gamma);
            const auto W = [&](double g) {
                Mat3 F = Mat3::Identity();
                F(0, 1) = g;
                return density->psi(F);
            };
            const double h = 1e-4;
            const double fd = (-W(gamma + 2 * h) + 8 * W(gamma + h) - 8 * W(gamma - h) + W(gamma - 2 * h)) / (12 * h);
            EXPECT_NEAR(r.shearStress, fd, 1e-6 * 1.2e4) << label << " gamma " << gamma;
            Mat3 F = Mat3::Identity();
            F(0, 1) = gamma;
            const Mat3 P = density->stress(F);
            EXPECT_EQ(r.normalStress[0], P(0, 0));
            EXPECT_EQ(r.normalStress[1], P(1, 1));
            EXPECT_EQ(r.normalStress[2], P(2, 2));
        }
    }
    // Neo-Hookean in simple shear (J = 1): P12 = μγ exactly.
    const NeoHookeanDensity nh(1e3, 1e4);
    EXPECT_NEAR(simpleShearStress(nh, 0.7).shearStress, 700.0, 1e-9);
}

TEST(MaterialResponse, NoUniaxialStateFailsClearlyAndFinitely) {
    const ConstantStressDensity positive(5.0);
    const UniaxialResponse r = solveUniaxial(positive, 1.2);
    EXPECT_FALSE(r.solved);
    EXPECT_EQ(r.nominalStress, 0.0);
    EXPECT_EQ(r.lateralStretch, 1.0);
    EXPECT_THAT(messageOf([&] { uniaxialNominalStress(positive, 1.2); }),
                HasSubstr("sim::uniaxialNominalStress(): density 'constant_stress', stretch 1.2: no lateral stretch "
                          "in [1e-06, 0.912871] frees the lateral faces (P22 = 5 Pa at t = 1e-06, 5 Pa at t = "
                          "0.912871)"));
    const ConstantStressDensity negative(-5.0);
    EXPECT_THAT(messageOf([&] { uniaxialNominalStress(negative, 0.5); }),
                HasSubstr("no lateral stretch in [1.41421, 1e+06] frees the lateral faces"));
    const NanDensity nan;
    EXPECT_FALSE(solveUniaxial(nan, 1.1).solved);
    EXPECT_THAT(messageOf([&] { uniaxialNominalStress(nan, 1.1); }),
                HasSubstr("density 'nan', stretch 1.1: the lateral stress is not finite"));
    EXPECT_THAT(messageOf([&] { uniaxialNominalStress(positive, -1.0); }),
                HasSubstr("sim::uniaxialNominalStress(): stretch -1 must be finite and positive"));
    EXPECT_THAT(messageOf([&] { simpleShearStress(positive, std::nan("")); }),
                HasSubstr("sim::simpleShearStress(): shear nan must be finite"));

    ResponseCurves curves = sampleResponses(positive, {.stretchCount = 5, .shearCount = 3});
    EXPECT_EQ(curves.unsolved, 5);
    for (double s : curves.nominalStress)
        EXPECT_EQ(s, 0.0);
}

TEST(MaterialResponse, SamplerCoversTheRangesAndMatchesPointwiseSolves) {
    const ValanisLandelDensity vl("nh", editableCurves("neo_hookean", 3e3, 0.45));
    const ResponseCurves c = sampleResponses(vl);
    ASSERT_EQ(c.stretch.size(), 101u);
    ASSERT_EQ(c.shear.size(), 101u);
    EXPECT_EQ(c.stretch.front(), 0.6);
    EXPECT_EQ(c.stretch.back(), 1.6);
    EXPECT_EQ(c.shear.front(), 0.0);
    EXPECT_EQ(c.shear.back(), 1.0);
    EXPECT_EQ(c.unsolved, 0);
    for (std::size_t i = 0; i < c.stretch.size(); ++i) {
        EXPECT_EQ(c.solved[i], 1);
        // Warm-started: the same root as a cold solve, to rounding.
        const UniaxialResponse cold = uniaxialNominalStress(vl, c.stretch[i]);
        EXPECT_NEAR(c.nominalStress[i], cold.nominalStress, 1e-9 * 3e3);
        EXPECT_NEAR(c.lateralStretch[i], cold.lateralStretch, 1e-12);
        if (i > 0) {
            EXPECT_GT(c.nominalStress[i], c.nominalStress[i - 1]);
            EXPECT_GT(c.shearStress[i], c.shearStress[i - 1]);
        }
    }
    EXPECT_THAT(messageOf([&] { sampleResponses(vl, {.stretchMin = 0.0}); }),
                HasSubstr("sim::sampleResponsesInto(): stretch range [0, 1.6] must be finite with 0 < stretchMin < "
                          "stretchMax"));
    EXPECT_THAT(messageOf([&] { sampleResponses(vl, {.shearMax = -1.0}); }), HasSubstr("shearMax -1 must be"));
    EXPECT_THAT(messageOf([&] { sampleResponses(vl, {.stretchCount = -1}); }), HasSubstr("must not be negative"));
    const ResponseCurves none = sampleResponses(vl, {.stretchCount = 0, .shearCount = 1});
    EXPECT_TRUE(none.stretch.empty());
    ASSERT_EQ(none.shear.size(), 1u);
    EXPECT_EQ(none.shearStress[0], 0.0);
}

TEST(MaterialResponse, SamplingCostPerDragEvent) {
    // The editor samples on every drag event: figure recorded, not asserted (no timed asserts).
    const ValanisLandelDensity vl("nh", editableCurves("neo_hookean", 3e3, 0.45));
    ResponseCurves c;
    const ResponseSampling sampling{.stretchCount = 100, .shearCount = 100};
    sampleResponsesInto(vl, sampling, c);
    constexpr int kRuns = 200;
    const auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < kRuns; ++i)
        sampleResponsesInto(vl, sampling, c);
    const double us = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count() / kRuns;
    const UniaxialResponse one = uniaxialNominalStress(vl, 1.4);
    EXPECT_LT(one.evaluations, 60);
    RecordProperty("sample_100_uniaxial_100_shear_us", sci(us));
    RecordProperty("uniaxial_cold_solve_evaluations", std::to_string(one.evaluations));
    EXPECT_EQ(c.unsolved, 0);
}

TEST(MaterialResponse, EquibiaxialAndPlanarShearAreTheDerivativeOfTheEnergyAlongTheirTests) {
    // F = diag(λ, λ, t) and diag(λ, 1, t) with the free face P33 = 0: the Ψ-gradient there
    // vanishes and its x component is the test's nominal stress P11 (central differences of Ψ),
    // every density, stretch 0.85–1.15.
    for (const LoadCase c : {LoadCase::Equibiaxial, LoadCase::PlanarShear}) {
        for (const auto& [label, density, invariant] : allDensities(1e3, 1e4)) {
            for (double s : stretches(0.85, 1.15, 13)) { // St. Venant–Kirchhoff has no equibiaxial state at 1.3
                const UniaxialResponse u = solveLoadCase(*density, c, s);
                ASSERT_TRUE(u.solved) << loadCaseName(c) << " " << label << " stretch " << s;
                const double y = c == LoadCase::Equibiaxial ? s : 1.0;
                const Mat3 F = Eigen::Vector3d(s, y, u.lateralStretch).asDiagonal();
                const Mat3 g = centralDifference([&](const Mat3& G) { return density->psi(G); }, F);
                const double scale = 1e4 + 2e3;
                EXPECT_LT(std::abs(g(2, 2)), 1e-6 * scale) << loadCaseName(c) << " " << label << " stretch " << s;
                EXPECT_NEAR(g(0, 0), u.nominalStress, 1e-6 * scale) << loadCaseName(c) << " " << label;
                if (c == LoadCase::Equibiaxial) EXPECT_NEAR(g(1, 1), u.nominalStress, 1e-6 * scale) << label;
            }
        }
    }
    // the uniaxial case is solveUniaxial itself
    auto nh = makeEnergyDensity("neo_hookean", 1e3, 1e4);
    EXPECT_EQ(solveLoadCase(*nh, LoadCase::Uniaxial, 1.3).nominalStress, solveUniaxial(*nh, 1.3).nominalStress);
    EXPECT_STREQ(loadCaseName(LoadCase::PlanarShear), "planar shear");
}
