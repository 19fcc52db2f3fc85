// FitCurves::FPrimeKeepingPoisson: fitting f′ alone keeps the small-strain ν where the artist put
// it (h′ scaled with the fitted shear stiffness), with one test or two, however stiff the data.
#include "sim/material/curve_fit.hpp"
#include "sim/material/editable_curves.hpp"
#include "sim/material/laws.hpp"
#include "sim/material/material_response.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

using namespace viscera::sim;

namespace {

/// `count` rows of the analytic compressible Neo-Hookean law (μ, λ) under load case `c` over [lo, hi].
UniaxialData neoHookeanTest(double mu, double lambda, LoadCase c, double lo, double hi, int count) {
    auto nh = makeEnergyDensity("neo_hookean", mu, lambda);
    UniaxialData d;
    for (int i = 0; i < count; ++i) {
        const double s = lo + (hi - lo) * i / (count - 1);
        d.stretch.push_back(s);
        d.nominalStress.push_back(solveLoadCase(*nh, c, s).nominalStress);
        d.line.push_back(i + 1);
    }
    return d;
}

} // namespace

TEST(FitKeepsPoisson, OneTestOrTwoTheArtistsNuStaysAndEFollowsTheData) {
    // Start: the Neo-Hookean preset at E 3 kPa, ν 0.45 (nearly incompressible tissue). Data: a
    // stiffer, more compressible Neo-Hookean (μ 5 kPa, λ 7.5 kPa: E 13 kPa, ν 0.3) — left to
    // itself a fit of f′ alone would drag ν far from 0.45.
    const double mu = 5e3, lambda = 7.5e3;
    const ValanisLandelCurves start = editableCurves("neo_hookean", 3e3, 0.45);
    const double nu0 = smallStrainConstants(start).poissonRatio;
    ASSERT_NEAR(nu0, 0.45, 1e-4); // the preset's curves approximate the law
    const UniaxialData uni = neoHookeanTest(mu, lambda, LoadCase::Uniaxial, 0.8, 1.3, 21);
    const UniaxialData both =
        combineTests({{LoadCase::Uniaxial, uni},
                      {LoadCase::Equibiaxial, neoHookeanTest(mu, lambda, LoadCase::Equibiaxial, 0.9, 1.2, 15)}});
    FitOptions opt;
    opt.curves = FitCurves::FPrimeKeepingPoisson;
    for (const UniaxialData* data : {&uni, &both}) {
        const std::string tag = data == &uni ? "one test" : "two tests";
        const CurveFitResult r = fitUniaxial(start, *data, opt);
        const SmallStrainConstants k = smallStrainConstants(r.curves);
        EXPECT_NEAR(k.poissonRatio, nu0, 1e-9) << tag;
        // f′ moved: the shear stiffness rose toward the data's (the start's μ is ~1 kPa)
        EXPECT_GT(k.youngsModulus, 2 * 3e3) << tag;
        EXPECT_TRUE(std::isfinite(r.sse)) << tag;
        EXPECT_GT(r.rSquared, 0.9) << tag;
        // the rest points of every curve stay exactly (no stress at rest)
        for (auto member : {&ValanisLandelCurves::fPrime, &ValanisLandelCurves::hPrime}) {
            const auto& c = r.curves.*member;
            const auto& s = start.*member;
            ASSERT_TRUE(c && s) << tag;
            ASSERT_EQ(c->size(), s->size()) << tag;
            EXPECT_NO_THROW(c->validate()) << tag;
            for (std::size_t i = 0; i < c->size(); ++i)
                if (c->controlPoints()[i].x == 1.0) EXPECT_EQ(c->controlPoints()[i].y, s->controlPoints()[i].y) << tag;
        }
        // the plain f′ fit of the same data does move ν: the option is what keeps it
        FitOptions plain;
        plain.curves = FitCurves::FPrime;
        const double nuPlain = smallStrainConstants(fitUniaxial(start, *data, plain).curves).poissonRatio;
        EXPECT_GT(std::abs(nuPlain - nu0), 0.01) << tag;
    }
}

TEST(FitKeepsPoisson, AStartWithoutAnHPrimeIsRefusedNamingTheRule) {
    ValanisLandelCurves start = editableCurves("neo_hookean", 3e3, 0.45);
    start.hPrime.reset();
    FitOptions opt;
    opt.curves = FitCurves::FPrimeKeepingPoisson;
    try {
        fitUniaxial(start, neoHookeanTest(1e3, 1e4, LoadCase::Uniaxial, 0.8, 1.3, 11), opt);
        FAIL() << "no h' accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("no h' rising at 1"), std::string::npos) << e.what();
    }
}
