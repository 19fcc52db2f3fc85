#include "material_test_support.hpp"

#include "sim/material/curve_fit.hpp"
#include "sim/material/editable_curves.hpp"
#include "sim/material/laws.hpp"
#include "sim/material/material_response.hpp"
#include "sim/util/error.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>

using namespace viscera::sim;
using namespace viscera::sim::testing;
using ::testing::HasSubstr;

namespace {

/// Synthetic uniaxial data of the analytic compressible Neo-Hookean law: `count` stretches over
/// [lo, hi], the lateral stretch solved independently (bisection on μ(t² − 1) + λ log(λt²) = 0).
UniaxialData neoHookeanData(double mu, double lambda, double lo, double hi, int count) {
    UniaxialData d;
    for (int i = 0; i < count; ++i) {
        const double s = lo + (hi - lo) * i / (count - 1);
        double a = 1e-3, b = 1e3;
        for (int k = 0; k < 200; ++k) {
            const double c = 0.5 * (a + b);
            if (c == a || c == b) break;
            (mu * (c * c - 1) + lambda * std::log(s * c * c) < 0 ? a : b) = c;
        }
        const double t = 0.5 * (a + b);
        d.stretch.push_back(s);
        d.nominalStress.push_back(mu * (s - 1 / s) + lambda * std::log(s * t * t) / s);
        d.line.push_back(i + 1);
    }
    return d;
}

/// E of Lamé μ, λ.
double youngs(double mu, double lambda) {
    return mu * (3 * lambda + 2 * mu) / (lambda + mu);
}

/// The shape rule and the rest state of fitted curves against the start.
void expectShapeAndRest(const ValanisLandelCurves& fit, const ValanisLandelCurves& start, const std::string& what) {
    for (auto member : {&ValanisLandelCurves::fPrime, &ValanisLandelCurves::gPrime, &ValanisLandelCurves::hPrime}) {
        const auto& c = fit.*member;
        const auto& s = start.*member;
        ASSERT_EQ(c.has_value(), s.has_value()) << what;
        if (!c) continue;
        ASSERT_EQ(c->size(), s->size()) << what;
        EXPECT_EQ(c->shape(), s->shape()) << what;
        EXPECT_NO_THROW(c->validate()) << what;
        for (std::size_t k = 0; k < c->size(); ++k) {
            const CurvePoint p = c->controlPoints()[k], q = s->controlPoints()[k];
            EXPECT_EQ(p.x, q.x) << what;
            EXPECT_TRUE(std::isfinite(p.y)) << what;
            if (p.x == 1.0) {
                EXPECT_EQ(p.y, q.y) << what << ": rest point moved";
            }
            if (k > 0 && c->shape() == CurveShape::StrictlyIncreasing) {
                EXPECT_GT(p.y, c->controlPoints()[k - 1].y) << what << " " << c->name() << " point " << k;
            }
        }
        if (c->shape() == CurveShape::StrictlyIncreasing) {
            const double lo = c->controlPoints().front().x, hi = c->controlPoints().back().x;
            double scale = 0;
            for (const CurvePoint& p : c->controlPoints())
                scale = std::max(scale, std::abs(p.y));
            double prev = c->value(lo);
            for (int i = 1; i <= 2000; ++i) {
                const double v = c->value(lo + (hi - lo) * i / 2000);
                EXPECT_GE(v, prev - 1e-12 * scale) << what << " " << c->name(); // non-decreasing up to rounding
                prev = v;
            }
        }
    }
    const RestNormalization rest = restNormalization(fit);
    EXPECT_TRUE(rest.balanced) << what;
    EXPECT_EQ(rest.restStress, restNormalization(start).restStress) << what;
    EXPECT_NO_THROW(ValanisLandelDensity("fit", fit)) << what;
}

} // namespace

TEST(CurveFit, NeoHookeanDataFromADifferentPreset) {
    // Acceptance: data μ = 1 kPa, λ = 10 kPa (E = 2909 Pa, ν = 0.4545), stretch 0.7–1.5, 41
    // points; start from the Neo-Hookean preset with E × 2 and ν = 0.3, and with E / 2, ν = 0.3.
    const double mu = 1e3, lambda = 1e4;
    const UniaxialData data = neoHookeanData(mu, lambda, 0.7, 1.5, 41);
    const double E = youngs(mu, lambda);
    for (const double factor : {2.0, 0.5}) {
        const ValanisLandelCurves start = editableCurves("neo_hookean", factor * E, 0.3);
        const auto t0 = std::chrono::steady_clock::now();
        const CurveFitResult r = fitUniaxial(start, data);
        const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        const std::string tag = factor > 1 ? "stiff_start" : "soft_start";
        RecordProperty("fit_nh_" + tag + "_ms", sci(ms));
        RecordProperty("fit_nh_" + tag + "_sse_pa2", sci(r.sse));
        RecordProperty("fit_nh_" + tag + "_one_minus_r2", sci(1.0 - r.rSquared));
        RecordProperty("fit_nh_" + tag + "_max_rel_error", sci(r.maxRelativeError));
        RecordProperty("fit_nh_" + tag + "_iterations", std::to_string(r.iterations));
        RecordProperty("fit_nh_" + tag + "_evaluations", std::to_string(r.evaluations));
        RecordProperty("fit_nh_" + tag + "_stop", std::to_string(static_cast<int>(r.stop)));
        EXPECT_TRUE(r.converged) << tag;
        EXPECT_GT(r.rSquared, 0.999) << tag;
        EXPECT_LT(r.maxRelativeError, 0.01) << tag;
        EXPECT_DOUBLE_EQ(r.stretchMin, 0.7);
        EXPECT_DOUBLE_EQ(r.stretchMax, 1.5);
        ASSERT_EQ(r.fittedStress.size(), data.size());
        for (std::size_t i = 0; i < data.size(); ++i)
            EXPECT_LE(std::abs(r.fittedStress[i] - data.nominalStress[i]),
                      0.01 * std::max(std::abs(data.nominalStress[i]), r.relativeErrorFloor))
                << tag << " stretch " << data.stretch[i];
        expectShapeAndRest(r.curves, start, tag);
        // The figures are those of the returned curves.
        const ValanisLandelDensity fitted("fit", r.curves);
        double sse = 0;
        for (std::size_t i = 0; i < data.size(); ++i) {
            const double e = uniaxialNominalStress(fitted, data.stretch[i]).nominalStress - data.nominalStress[i];
            sse += e * e;
        }
        EXPECT_NEAR(sse, r.sse, 1e-9 * sse + 1e-12);
    }
}

TEST(CurveFit, DeterministicAndNeverBreaksTheShapeRule) {
    const UniaxialData data = neoHookeanData(1e3, 1e4, 0.7, 1.5, 41);
    for (const FitCurves which : {FitCurves::FPrime, FitCurves::FPrimeAndHPrime}) {
        for (const FitWeighting weighting : {FitWeighting::Absolute, FitWeighting::Relative}) {
            for (const char* law : {"neo_hookean", "corotated", "st_venant_kirchhoff"}) {
                const ValanisLandelCurves start = editableCurves(law, 6e3, 0.3);
                if (which == FitCurves::FPrimeAndHPrime && !start.hPrime) continue;
                const FitOptions options{.curves = which, .weighting = weighting, .maxIterations = 40};
                const CurveFitResult a = fitUniaxial(start, data, options);
                const CurveFitResult b = fitUniaxial(start, data, options);
                const std::string what = std::string(law) + (which == FitCurves::FPrime ? " f'" : " f'h'") +
                                         (weighting == FitWeighting::Relative ? " relative" : " absolute");
                EXPECT_EQ(a.sse, b.sse) << what;
                EXPECT_EQ(a.iterations, b.iterations) << what;
                EXPECT_EQ(a.fittedStress, b.fittedStress) << what;
                expectShapeAndRest(a.curves, start, what);
                EXPECT_TRUE(std::isfinite(a.sse) && std::isfinite(a.rSquared)) << what;
                // The fit improves on its start.
                const ValanisLandelDensity s(law, start);
                double sse0 = 0;
                for (std::size_t i = 0; i < data.size(); ++i) {
                    const double e = uniaxialNominalStress(s, data.stretch[i]).nominalStress - data.nominalStress[i];
                    sse0 += e * e;
                }
                EXPECT_LT(a.sse, sse0) << what;
                RecordProperty("fit_one_minus_r2_" + std::string(law) + (which == FitCurves::FPrime ? "_f" : "_fh") +
                                   (weighting == FitWeighting::Relative ? "_rel" : "_abs"),
                               sci(1.0 - a.rSquared));
            }
        }
    }
}

TEST(CurveFit, ExtremeAndNoisyDataGiveFiniteCurves) {
    const ValanisLandelCurves start = editableCurves("neo_hookean", 3e3, 0.45);
    // 1e5 times stiffer than the start.
    {
        const UniaxialData stiff = neoHookeanData(1e8, 1e9, 0.7, 1.5, 21);
        const CurveFitResult r = fitUniaxial(start, stiff, {.maxIterations = 60});
        expectShapeAndRest(r.curves, start, "stiff");
        EXPECT_TRUE(std::isfinite(r.sse));
        EXPECT_TRUE(std::isfinite(r.maxRelativeError));
        RecordProperty("fit_stiff_one_minus_r2", sci(1.0 - r.rSquared));
        RecordProperty("fit_stiff_max_rel_error", sci(r.maxRelativeError));
    }
    // ±10 % deterministic noise on every point.
    {
        UniaxialData noisy = neoHookeanData(1e3, 1e4, 0.7, 1.5, 41);
        std::mt19937 rng(7);
        std::uniform_real_distribution<double> u(-0.1, 0.1);
        for (double& s : noisy.nominalStress)
            s *= 1 + u(rng);
        const CurveFitResult r = fitUniaxial(start, noisy);
        expectShapeAndRest(r.curves, start, "noisy");
        EXPECT_TRUE(std::isfinite(r.sse));
        EXPECT_GT(r.rSquared, 0.9);
        RecordProperty("fit_noisy_one_minus_r2", sci(1.0 - r.rSquared));
    }
    // Data no monotone material matches (stress falling with stretch): finite, valid curves.
    {
        UniaxialData wild = neoHookeanData(1e3, 1e4, 0.7, 1.5, 21);
        for (std::size_t i = 0; i < wild.size(); ++i)
            wild.nominalStress[i] = (i % 2 ? 1e7 : -1e7);
        const CurveFitResult r = fitUniaxial(start, wild, {.maxIterations = 30});
        expectShapeAndRest(r.curves, start, "wild");
        EXPECT_TRUE(std::isfinite(r.sse));
        for (double s : r.fittedStress)
            EXPECT_TRUE(std::isfinite(s));
    }
}

TEST(CurveFit, ReadsAFileAndFitsIt) {
    const auto dir = std::filesystem::temp_directory_path() / "viscera_test_curve_fit_file";
    std::filesystem::create_directories(dir);
    const UniaxialData synthetic = neoHookeanData(1e3, 1e4, 0.7, 1.5, 41);
    {
        std::ofstream out(dir / "nh.csv");
        out << "# synthetic Neo-Hookean, mu = 1 kPa, lambda = 10 kPa\nstrain;stress [Pa]\n";
        out.precision(17);
        for (std::size_t i = 0; i < synthetic.size(); ++i)
            out << synthetic.stretch[i] - 1.0 << ";" << synthetic.nominalStress[i] << "\n";
    }
    const UniaxialData data = readUniaxialData(dir / "nh.csv", StrainMeasure::EngineeringStrain);
    std::filesystem::remove_all(dir);
    ASSERT_EQ(data.size(), 41u);
    const CurveFitResult r = fitUniaxial(editableCurves("neo_hookean", 6e3, 0.3), data);
    EXPECT_GT(r.rSquared, 0.999);
    EXPECT_LT(r.maxRelativeError, 0.01);
}

TEST(CurveFit, PreconditionsAreChecked) {
    const UniaxialData data = neoHookeanData(1e3, 1e4, 0.7, 1.5, 11);
    const ValanisLandelCurves start = editableCurves("neo_hookean", 3e3, 0.45);
    UniaxialData few = data;
    few.stretch.resize(2);
    few.nominalStress.resize(2);
    EXPECT_THAT(messageOf([&] { fitUniaxial(start, few); }),
                HasSubstr("sim::fitUniaxial(): data has 2 rows, at least 3 are needed"));
    UniaxialData unsorted = data;
    std::swap(unsorted.stretch[3], unsorted.stretch[4]);
    EXPECT_THAT(messageOf([&] { fitUniaxial(start, unsorted); }), HasSubstr("data row 4: stretch"));
    EXPECT_THAT(messageOf([&] { fitUniaxial(start, data, {.maxIterations = 0}); }),
                HasSubstr("maxIterations 0 must be at least 1"));
    EXPECT_THAT(messageOf([&] { fitUniaxial(editableCurves("corotated", 3e3, 0.3), data); }),
                HasSubstr("the start curves have no h' to fit (use FitCurves::FPrime)"));
    ValanisLandelCurves noRest = authoredTissueCurves();
    noRest.fPrime = MonotoneCurve("f'", {{0.5, -300}, {0.9, 100}, {1.1, 300}, {2.0, 2000}});
    noRest.hPrime = MonotoneCurve("h'", {{0.5, -1000}, {1.0, -500}, {2.0, 500}});
    EXPECT_THAT(messageOf([&] { fitUniaxial(noRest, data); }),
                HasSubstr("sim::fitUniaxial(): curve f' has no control point at x = 1 (the pinned rest point)"));
    ValanisLandelCurves unbalanced = start;
    unbalanced.fPrime->setControlPoint(4, 1.0, 1100.0);
    EXPECT_THAT(messageOf([&] { fitUniaxial(unbalanced, data); }),
                HasSubstr("sim::fitUniaxial(): start curves: material 'fit start': stress at rest"));
}

TEST(CurveFit, AnEquibiaxialTestBesideTheUniaxialOneIsFittedToo) {
    // Compressible Neo-Hookean data (μ = 1 kPa, λ = 10 kPa: E 2909 Pa, ν 0.4545) of a uniaxial and an
    // equibiaxial test, 21 points each; f′ and h′ fitted to both from the preset at 2E, ν 0.3. The
    // second test's rows are fitted with its own nominal stress.
    auto nh = makeEnergyDensity("neo_hookean", 1e3, 1e4);
    auto test = [&](LoadCase c, double lo, double hi) {
        UniaxialData d;
        for (int i = 0; i < 21; ++i) {
            const double s = lo + (hi - lo) * i / 20.0;
            d.stretch.push_back(s);
            d.nominalStress.push_back(solveLoadCase(*nh, c, s).nominalStress);
            d.line.push_back(i + 1);
        }
        return d;
    };
    const UniaxialData both = combineTests({{LoadCase::Uniaxial, test(LoadCase::Uniaxial, 0.7, 1.5)},
                                            {LoadCase::Equibiaxial, test(LoadCase::Equibiaxial, 0.85, 1.3)}});
    ASSERT_EQ(both.size(), 42u);
    ASSERT_EQ(both.loadCase.size(), 42u);
    EXPECT_EQ(both.loadCase.back(), LoadCase::Equibiaxial);
    FitOptions opt;
    opt.curves = FitCurves::FPrimeAndHPrime;
    const ValanisLandelCurves start = editableCurves("neo_hookean", 2 * youngs(1e3, 1e4), 0.3);
    // One uniaxial test leaves ν free (the same data fitted alone ends at ν 0.06 with R² 1); the
    // second test pins it. The fit is local: from the preset at ν 0.3 it stops at R² 0.995 (ν 0.37),
    // from ν 0.49 it reaches the data (the studio's dialog tries several starts).
    const CurveFitResult fromFar = fitUniaxial(start, both, opt);
    RecordProperty("fit_two_tests_from_nu_0_3_one_minus_r2", sci(1.0 - fromFar.rSquared));
    EXPECT_GT(fromFar.rSquared, 0.99);
    const ValanisLandelCurves near = editableCurves("neo_hookean", 2 * youngs(1e3, 1e4), 0.49);
    const CurveFitResult r = fitUniaxial(near, both, opt);
    RecordProperty("fit_two_tests_one_minus_r2", sci(1.0 - r.rSquared));
    RecordProperty("fit_two_tests_max_rel_error", sci(r.maxRelativeError));
    EXPECT_GT(r.rSquared, 0.999);
    EXPECT_LT(r.maxRelativeError, 0.1);
    EXPECT_DOUBLE_EQ(r.stretchMin, 0.7);
    EXPECT_DOUBLE_EQ(r.stretchMax, 1.5);
    const ValanisLandelDensity fitted("fit", r.curves);
    for (std::size_t i = 21; i < both.size(); ++i) // the equibiaxial rows, by the equibiaxial test
        EXPECT_NEAR(solveLoadCase(fitted, LoadCase::Equibiaxial, both.stretch[i]).nominalStress, r.fittedStress[i],
                    1e-9 * std::abs(r.fittedStress[i]) + 1e-9);
    const SmallStrainConstants k = smallStrainConstants(r.curves);
    RecordProperty("fit_two_tests_nu", sci(k.poissonRatio));
    EXPECT_NEAR(k.poissonRatio, 0.4545, 0.01) << "the second test pins the volume response";
    // a test mark per row or none
    UniaxialData broken = both;
    broken.loadCase.pop_back();
    EXPECT_THROW(fitUniaxial(start, broken, opt), std::invalid_argument);
}
