#include "material_test_support.hpp"

#include "sim/material/curve.hpp"
#include "sim/util/error.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace viscera::sim;
using ::testing::HasSubstr;
using viscera::sim::testing::messageOf;
using viscera::sim::testing::sci;

namespace {

/// A tissue-like f′: toe region, then a steep linear region (values in Pa).
std::vector<CurvePoint> toeCurve() {
    return {{0.3, -9000}, {0.6, -2500}, {0.9, -300}, {1.0, 0.0},  {1.05, 80},
            {1.1, 250},   {1.2, 1200},  {1.4, 6000}, {2.0, 30000}};
}

/// Simpson's rule on each cubic piece between consecutive breakpoints (exact for cubics), a
/// quadrature independent of the curve's antiderivative coefficients.
double simpsonIntegral(const MonotoneCurve& c, double a, double b) {
    std::vector<double> cuts{a};
    for (const auto& p : c.controlPoints())
        if (p.x > std::min(a, b) && p.x < std::max(a, b)) cuts.push_back(p.x);
    cuts.push_back(b);
    std::sort(cuts.begin(), cuts.end());
    if (a > b) std::reverse(cuts.begin(), cuts.end());
    double sum = 0;
    for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
        const double l = cuts[i], r = cuts[i + 1], m = 0.5 * (l + r);
        sum += (r - l) / 6.0 * (c.value(l) + 4.0 * c.value(m) + c.value(r));
    }
    return sum;
}

} // namespace

TEST(MonotoneCurve, InterpolatesControlPoints) {
    MonotoneCurve c("f'", toeCurve());
    for (const auto& p : toeCurve())
        EXPECT_NEAR(c.value(p.x), p.y, 1e-9 * std::abs(p.y) + 1e-9);
}

TEST(MonotoneCurve, StrictlyIncreasingDataGivesAMonotoneCurve) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    int checked = 0;
    for (int trial = 0; trial < 200; ++trial) {
        // Random increasing data with wildly varying secant slopes (steps and plateaus).
        std::vector<CurvePoint> pts;
        double x = -1.0 + u(rng), y = -100.0 * u(rng);
        const int n = 2 + trial % 12;
        for (int k = 0; k < n; ++k) {
            pts.push_back({x, y});
            x += 0.01 + u(rng);
            y += (u(rng) < 0.3 ? 1e-3 : 1.0) * std::pow(10.0, 3.0 * u(rng));
        }
        MonotoneCurve c("f'", pts);
        const double lo = pts.front().x - 1.0, hi = pts.back().x + 1.0;
        double prev = c.value(lo);
        for (int s = 1; s <= 4000; ++s) {
            const double xs = lo + (hi - lo) * s / 4000.0;
            const double v = c.value(xs);
            ASSERT_GE(v, prev) << "trial " << trial << " at x=" << xs;
            ASSERT_GE(c.derivative(xs), 0.0) << "trial " << trial << " at x=" << xs;
            prev = v;
            ++checked;
        }
        // Strict between the first and last control point.
        for (std::size_t k = 0; k + 1 < pts.size(); ++k) {
            const double a = pts[k].x, b = pts[k + 1].x;
            EXPECT_LT(c.value(a + 0.25 * (b - a)), c.value(a + 0.75 * (b - a)));
        }
    }
    EXPECT_EQ(checked, 200 * 4000);
}

TEST(MonotoneCurve, FilterIsWhatKeepsStepDataMonotone) {
    // A step: flat, jump, flat. Plain 4th-order Hermite overshoots; the filtered curve does not.
    const std::vector<CurvePoint> step{{0, 0}, {1, 0.001}, {2, 0.002}, {3, 10}, {4, 10.001}, {5, 10.002}};
    MonotoneCurve mono("f'", step);
    MonotoneCurve plain("f'", step, CurveShape::Unconstrained);
    double minSlopeMono = 1e300, minSlopePlain = 1e300;
    for (int s = 0; s <= 5000; ++s) {
        const double x = 5.0 * s / 5000.0;
        minSlopeMono = std::min(minSlopeMono, mono.derivative(x));
        minSlopePlain = std::min(minSlopePlain, plain.derivative(x));
    }
    EXPECT_GE(minSlopeMono, 0.0);
    EXPECT_LT(minSlopePlain, -0.5);
}

TEST(MonotoneCurve, DerivativeMatchesFiniteDifferencesOfValue) {
    MonotoneCurve c("f'", toeCurve());
    double worst = 0;
    for (int s = 0; s <= 1000; ++s) {
        const double x = 0.0 + 2.5 * s / 1000.0;
        bool nearKnot = false;
        for (const auto& p : c.controlPoints())
            nearKnot |= std::abs(x - p.x) < 1e-5;
        if (nearKnot) continue;
        const double h = 1e-6;
        const double fd = (c.value(x + h) - c.value(x - h)) / (2 * h);
        worst = std::max(worst, std::abs(fd - c.derivative(x)) / (std::abs(c.derivative(x)) + 1e3));
    }
    EXPECT_LT(worst, 1e-7);
}

TEST(MonotoneCurve, IntegralIsExactAgainstPiecewiseSimpson) {
    MonotoneCurve c("f'", toeCurve());
    const double pairs[][2] = {{1.0, 1.3},  {1.0, 0.45}, {0.31, 1.99}, {-2.0, 0.5}, {1.5, 4.0},
                               {-1.0, 5.0}, {5.0, -1.0}, {1.07, 1.08}, {2.5, 3.0},  {-3, -2}};
    double worst = 0;
    for (const auto& ab : pairs) {
        const double exact = c.integral(ab[0], ab[1]);
        const double numeric = simpsonIntegral(c, ab[0], ab[1]);
        const double err = std::abs(exact - numeric) / std::max(1.0, std::abs(numeric));
        worst = std::max(worst, err);
        EXPECT_NEAR(c.integral(ab[1], ab[0]), -exact, 1e-12 * std::max(1.0, std::abs(exact)));
    }
    EXPECT_LT(worst, 1e-12);
    ::testing::Test::RecordProperty("max_rel_error_integral_vs_simpson", sci(worst));
    // Additivity and the antiderivative.
    EXPECT_NEAR(c.integral(0.2, 1.1) + c.integral(1.1, 2.7), c.integral(0.2, 2.7), 1e-9);
    EXPECT_NEAR(c.antiderivative(1.7) - c.antiderivative(0.4), c.integral(0.4, 1.7), 1e-9);
    EXPECT_DOUBLE_EQ(c.integral(1.0, 1.0), 0.0);
}

TEST(MonotoneCurve, LinearExtrapolationIsC1AtBothEnds) {
    MonotoneCurve c("f'", toeCurve());
    const auto& p = c.controlPoints();
    for (double end : {p.front().x, p.back().x}) {
        // C1: one-sided difference quotients agree (no kink), and so do the derivatives.
        const double e = 1e-6, slope = c.derivative(end);
        const double left = (c.value(end) - c.value(end - e)) / e;
        const double right = (c.value(end + e) - c.value(end)) / e;
        EXPECT_NEAR(left, right, 1e-4 * std::abs(slope));
        EXPECT_NEAR(c.derivative(end - 1e-9), c.derivative(end + 1e-9), 1e-6 * std::abs(slope));
    }
    // Outside: exactly linear with the end slope.
    const double x0 = p.front().x, y0 = p.front().y, m0 = c.slopes().front();
    const double xn = p.back().x, yn = p.back().y, mn = c.slopes().back();
    for (double d : {0.1, 1.0, 10.0}) {
        EXPECT_NEAR(c.value(x0 - d), y0 - m0 * d, 1e-9 * (std::abs(y0) + m0 * d));
        EXPECT_NEAR(c.value(xn + d), yn + mn * d, 1e-9 * (std::abs(yn) + mn * d));
        EXPECT_DOUBLE_EQ(c.derivative(x0 - d), m0);
        EXPECT_DOUBLE_EQ(c.derivative(xn + d), mn);
        EXPECT_NEAR(c.integral(x0 - d, x0), d * y0 - 0.5 * m0 * d * d, 1e-12 * (std::abs(d * y0) + m0 * d * d));
    }
    EXPECT_GT(m0, 0.0);
    EXPECT_GT(mn, 0.0);
    // Finite for any finite x, including negative stretches.
    EXPECT_TRUE(std::isfinite(c.value(-1e6)) && std::isfinite(c.integral(1.0, -1e6)));
}

TEST(MonotoneCurve, ReproducesCubicsExactlyInsideTheRange) {
    const auto cubic = [](double x) { return 2.0 * x * x * x - 3.0 * x + 0.5; };
    auto c = MonotoneCurve::fit(
        "f'", cubic,
        {.xmin = -2, .xmax = 2, .count = 9, .spacing = CurveSpacing::Uniform, .shape = CurveShape::Unconstrained});
    double worst = 0;
    for (int s = 0; s <= 400; ++s) {
        const double x = -2 + 4.0 * s / 400;
        worst = std::max(worst, std::abs(c.value(x) - cubic(x)));
    }
    EXPECT_LT(worst, 1e-12);
}

TEST(MonotoneCurve, FitGeometricConvergesAtFourthOrder) {
    // The Neo-Hookean h′ (μ = 1, λ = 10) over J in [0.01, 100]; error relative to
    // max(μ + λ, |h′|).
    const auto fn = [](double J) { return (10.0 * std::log(J) - 1.0) / J; };
    std::vector<double> errors;
    for (int count : {101, 201, 401, 801, 1201}) {
        auto c = MonotoneCurve::fit("h'", fn,
                                    {.xmin = 1e-2,
                                     .xmax = 1e2,
                                     .count = count,
                                     .spacing = CurveSpacing::Geometric,
                                     .shape = CurveShape::Unconstrained});
        ASSERT_EQ(c.size(), static_cast<std::size_t>(count));
        // Geometric: constant ratio between consecutive abscissae.
        const auto& p = c.controlPoints();
        EXPECT_NEAR(p[1].x / p[0].x, p[count - 1].x / p[count - 2].x, 1e-12);
        EXPECT_DOUBLE_EQ(p.front().x, 1e-2);
        EXPECT_DOUBLE_EQ(p.back().x, 1e2);
        double worst = 0;
        for (int s = 0; s <= 20000; ++s) {
            const double J = 1e-2 * std::pow(1e4, s / 20000.0);
            worst = std::max(worst, std::abs(c.value(J) - fn(J)) / std::max(11.0, std::abs(fn(J))));
        }
        errors.push_back(worst);
        ::testing::Test::RecordProperty("fit_rel_error_count_" + std::to_string(count), sci(worst));
    }
    // Halving the spacing divides the error by ~16.
    for (std::size_t i = 0; i + 2 < errors.size(); ++i)
        EXPECT_GT(errors[i] / errors[i + 1], 12.0);
    EXPECT_LT(errors[3], 1e-8); // 801 points
    EXPECT_LT(errors[4], 2e-9); // 1201 points, the Neo-Hookean preset
}

TEST(MonotoneCurve, FitRejectsBadSpecsAndNonIncreasingSamples) {
    const auto id = [](double x) { return x; };
    EXPECT_THROW(MonotoneCurve::fit("f'", id, {.xmin = 0, .xmax = 1, .count = 5}),
                 std::invalid_argument); // geometric needs xmin > 0
    EXPECT_THROW(MonotoneCurve::fit("f'", id, {.xmin = 1, .xmax = 1, .count = 5}), std::invalid_argument);
    EXPECT_THROW(MonotoneCurve::fit("f'", id, {.xmin = 1, .xmax = 2, .count = 1}), std::invalid_argument);
    const std::string msg = messageOf([] {
        MonotoneCurve::fit("h'", [](double x) { return -x; },
                           {.xmin = 1, .xmax = 2, .count = 3, .spacing = CurveSpacing::Uniform});
    });
    EXPECT_EQ(msg, "curve h': control point 1 (x=1.5, y=-1.5) does not increase over point 0 "
                   "(y=-1)");
    EXPECT_THAT(messageOf([] {
                    MonotoneCurve::fit("h'", [](double x) { return std::log(x - 1.5); },
                                       {.xmin = 1, .xmax = 2, .count = 3});
                }),
                ::testing::Eq("curve h': control point 0 (x=1, y=nan) is not finite"));
}

TEST(MonotoneCurve, RejectionMessagesNameTheCurveAndThePoint) {
    const std::vector<CurvePoint> bad{{0.5, -3}, {0.8, -1}, {1.0, 0.7}, {1.2, 0.5}, {1.5, 2}};
    EXPECT_EQ(messageOf([&] { MonotoneCurve("h'", bad, CurveShape::StrictlyIncreasing, "material 'liver'"); }),
              "material 'liver': curve h': control point 3 (x=1.2, y=0.5) does not increase over "
              "point 2 (y=0.7)");
    EXPECT_THROW(MonotoneCurve("h'", bad), viscera::InputError);
    EXPECT_NO_THROW(MonotoneCurve("h'", bad, CurveShape::Unconstrained));

    EXPECT_EQ(messageOf([] {
                  MonotoneCurve("f'", {{1, 0}, {0.9, 1}});
              }),
              "curve f': control point 1 (x=0.9, y=1) does not lie right of point 0 (x=1)");
    EXPECT_EQ(messageOf([] {
                  MonotoneCurve("g'", {{1, 0}, {2, INFINITY}});
              }),
              "curve g': control point 1 (x=2, y=inf) is not finite");
    EXPECT_EQ(messageOf([] { MonotoneCurve("g'", {{1, 0}}); }), "curve g': needs at least 2 control points (has 1)");
}

TEST(MonotoneCurve, EditsValidateAndLeaveTheCurveUnchangedOnFailure) {
    MonotoneCurve c("f'", toeCurve(), CurveShape::StrictlyIncreasing, "material 'fascia'");
    const double before = c.value(1.15);
    EXPECT_EQ(messageOf([&] { c.setControlPoint(5, 1.1, -500); }),
              "material 'fascia': curve f': control point 5 (x=1.1, y=-500) does not increase "
              "over point 4 (y=80)");
    EXPECT_EQ(c.controlPoints()[5].y, 250);
    EXPECT_DOUBLE_EQ(c.value(1.15), before);
    EXPECT_THROW(c.setControlPoint(99, 1, 1), std::out_of_range);

    c.setControlPoint(5, 1.1, 400); // valid: changes the shape
    EXPECT_DOUBLE_EQ(c.value(1.1), 400);

    const std::size_t idx = c.insertControlPoint(1.02, 30);
    EXPECT_EQ(idx, 4u);
    EXPECT_EQ(c.size(), toeCurve().size() + 1);
    EXPECT_DOUBLE_EQ(c.value(1.02), 30);
    EXPECT_THAT(messageOf([&] { c.insertControlPoint(1.03, -1000); }),
                HasSubstr("curve f': control point 5 (x=1.03, y=-1000) does not increase over "
                          "point 4 (y=30)"));
    EXPECT_THAT(messageOf([&] { c.insertControlPoint(1.02, 35); }),
                HasSubstr("does not lie right of point 4 (x=1.02)"));

    c.removeControlPoint(idx);
    EXPECT_EQ(c.size(), toeCurve().size());
    EXPECT_THROW(c.removeControlPoint(42), std::out_of_range);
    MonotoneCurve two("g'", {{0, 0}, {1, 1}});
    EXPECT_EQ(messageOf([&] { two.removeControlPoint(0); }), "curve g': needs at least 2 control points (has 1)");
    EXPECT_EQ(two.size(), 2u);
}
