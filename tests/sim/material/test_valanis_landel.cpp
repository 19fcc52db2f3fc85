#include "material_test_support.hpp"

#include "sim/material/laws.hpp"
#include "sim/material/valanis_landel.hpp"
#include "sim/util/error.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

using namespace viscera::sim;
using namespace viscera::sim::testing;
using ::testing::HasSubstr;

namespace {

/// Analytic compressible Neo-Hookean for J > 0 (no extension), written out independently.
double nhPsi(const Mat3& F, double mu, double lambda) {
    const double J = F.determinant(), l = std::log(J);
    return 0.5 * mu * (F.squaredNorm() - 3.0) - mu * l + 0.5 * lambda * l * l;
}
Mat3 nhStress(const Mat3& F, double mu, double lambda) {
    const Mat3 Finv = F.inverse().transpose();
    return mu * (F - Finv) + lambda * std::log(F.determinant()) * Finv;
}

} // namespace

TEST(SignedSvd, ProperRotationsAndSignedSmallestStretch) {
    std::vector<Mat3> Fs;
    for (const auto& s : sampleDeformations(10, 3))
        Fs.push_back(s.F);
    Fs.push_back(Eigen::Vector3d(1, 1, -1).asDiagonal());
    Fs.push_back(-Mat3::Identity());
    Fs.push_back(Eigen::Vector3d(2, 1, 0).asDiagonal());
    Fs.push_back(Mat3::Zero());
    for (const Mat3& F : Fs) {
        const SignedSvd s = signedSvd(F);
        EXPECT_NEAR(s.U.determinant(), 1.0, 1e-12);
        EXPECT_NEAR(s.V.determinant(), 1.0, 1e-12);
        EXPECT_LT((s.U * s.sigma.asDiagonal() * s.V.transpose() - F).norm(), 1e-12 * (1 + F.norm()));
        EXPECT_GE(s.sigma(0), s.sigma(1));
        EXPECT_GE(s.sigma(1), std::abs(s.sigma(2)));
        if (std::abs(F.determinant()) > 1e-12) {
            EXPECT_EQ(s.sigma(2) < 0, F.determinant() < 0);
            EXPECT_NEAR(s.sigma.prod(), F.determinant(), 1e-12 * (1 + std::abs(F.determinant())));
        }
    }
}

TEST(ValanisLandel, NeoHookeanPresetMatchesAnalyticNeoHookean) {
    // Acceptance: principal stretches over [0.3, 3]³ (J from 0.027 to 27), random rotations,
    // every Lamé pair of the sweep; error relative to max(μ + λ, |value|).
    const std::vector<double> grid{0.3, 0.37, 0.45, 0.55, 0.68, 0.82, 1.0, 1.15, 1.35, 1.6, 1.9, 2.2, 2.6, 3.0};
    std::mt19937 rng(4);
    double worstPsi = 0, worstP = 0;
    int cases = 0;
    for (const Lame& m : lameSweep()) {
        const ValanisLandelDensity vl("nh", neoHookeanCurves(m.mu, m.lambda));
        const double scale = m.mu + m.lambda;
        for (double a : grid)
            for (double b : grid)
                for (double c : grid) {
                    const Mat3 F =
                        randomRotation(rng) * Eigen::Vector3d(a, b, c).asDiagonal() * randomRotation(rng).transpose();
                    const double psi = nhPsi(F, m.mu, m.lambda);
                    const Mat3 P = nhStress(F, m.mu, m.lambda);
                    const double ePsi = std::abs(vl.psi(F) - psi) / std::max(scale, std::abs(psi));
                    const double eP = (vl.stress(F) - P).norm() / std::max(scale, P.norm());
                    worstPsi = std::max(worstPsi, ePsi);
                    worstP = std::max(worstP, eP);
                    ++cases;
                }
    }
    EXPECT_EQ(cases, 12 * 14 * 14 * 14);
    EXPECT_LT(worstPsi, 1e-8);
    EXPECT_LT(worstP, 1e-8);
    RecordProperty("vl_nh_max_rel_psi", sci(worstPsi));
    RecordProperty("vl_nh_max_rel_P", sci(worstP));
}

TEST(ValanisLandel, NeoHookeanPresetMatchesTheAnalyticLawThroughInversion) {
    // Below J = 0.01 both forms extend h quadratically (the law exactly, the curve with its
    // estimated end slope); they stay close and finite through J ≤ 0.
    double worst = 0;
    for (const Lame& m : lameSweep()) {
        const ValanisLandelDensity vl("nh", neoHookeanCurves(m.mu, m.lambda));
        const NeoHookeanDensity law(m.mu, m.lambda, 1e-2);
        const double scale = m.mu + m.lambda;
        for (double t = 0.05; t >= -1.0; t -= 0.01) {
            const Mat3 F = Eigen::Vector3d(1.3, 0.9, t).asDiagonal();
            const double e1 = std::abs(vl.psi(F) - law.psi(F)) / std::max(scale, std::abs(law.psi(F)));
            const double e2 = (vl.stress(F) - law.stress(F)).norm() / std::max(scale, law.stress(F).norm());
            worst = std::max({worst, e1, e2});
        }
    }
    EXPECT_LT(worst, 1e-6);
    RecordProperty("vl_nh_vs_law_inverted_max_rel", sci(worst));
}

TEST(ValanisLandel, NeoHookeanPresetCurvesAndModuli) {
    for (const Lame& m : lameSweep()) {
        const auto curves = neoHookeanCurves(m.mu, m.lambda);
        ASSERT_TRUE(curves.fPrime && curves.hPrime);
        EXPECT_FALSE(curves.gPrime);
        EXPECT_EQ(curves.fPrime->size(), 9u);
        EXPECT_EQ(curves.hPrime->size(), 1201u);
        EXPECT_EQ(curves.fPrime->shape(), CurveShape::StrictlyIncreasing);
        // h′ = (λ log J − μ)/J falls beyond J = exp(1 + μ/λ) < 100.
        EXPECT_EQ(curves.hPrime->shape(), CurveShape::Unconstrained);
        const ValanisLandelDensity vl("nh", curves);
        // Moduli come from the curve slopes at 1 (5-point estimates): 4th-order accurate.
        EXPECT_NEAR(vl.shearModulus(), m.mu, 1e-7 * (m.mu + m.lambda));
        EXPECT_NEAR(vl.lameLambda(), m.lambda, 1e-7 * (m.mu + m.lambda));
        EXPECT_NEAR(vl.restStiffness(), m.lambda + 2 * m.mu, 1e-7 * (m.mu + m.lambda));
    }
    // Below the peak the same preset is a strictly increasing (authorable) curve.
    const auto narrow = neoHookeanCurves(1000, 1000, {.volumeMin = 0.05, .volumeMax = 5.0, .volumeCount = 301});
    EXPECT_EQ(narrow.hPrime->shape(), CurveShape::StrictlyIncreasing);
    EXPECT_EQ(neoHookeanCurves(1000, 0).hPrime->shape(), CurveShape::StrictlyIncreasing);
    EXPECT_THROW(neoHookeanCurves(-1, 1), std::invalid_argument);
}

TEST(ValanisLandel, RejectsAnUnbalancedRestStateNamingTheCurves) {
    ValanisLandelCurves c;
    c.fPrime = MonotoneCurve("f'", {{0.5, 500}, {1.0, 1000}, {2.0, 2000}});
    EXPECT_EQ(messageOf([&] { ValanisLandelDensity("liver", c); }),
              "material 'liver': stress at rest f'(1) + 2 g'(1) + h'(1) = 1000 Pa is not zero "
              "(f'(1)=1000, g' absent, h' absent)");
    c.hPrime = MonotoneCurve("h'", {{0.5, -1500}, {1.0, -999}, {2.0, 0}});
    EXPECT_THAT(messageOf([&] { ValanisLandelDensity("liver", c); }),
                HasSubstr("stress at rest f'(1) + 2 g'(1) + h'(1) = 1 Pa is not zero "
                          "(f'(1)=1000, g' absent, h'(1)=-999)"));
    EXPECT_THROW(ValanisLandelDensity("liver", c), viscera::InputError);
    // Balanced within the tolerance: accepted.
    c.hPrime->setControlPoint(1, 1.0, -1000 + 1e-8);
    EXPECT_NO_THROW(ValanisLandelDensity("liver", c));
    // Only a volume term: no shear stiffness.
    ValanisLandelCurves h;
    h.hPrime = MonotoneCurve("h'", {{0.5, -1000}, {1.0, 0}, {2.0, 1000}});
    EXPECT_THAT(messageOf([&] { ValanisLandelDensity("gel", h); }), HasSubstr("material 'gel': shear modulus at rest"));
    EXPECT_THAT(messageOf([] { ValanisLandelDensity("void", {}); }), HasSubstr("material 'void': stiffness at rest"));
}

TEST(ValanisLandel, CurveErrorsCarryTheMaterialName) {
    auto c = authoredTissueCurves();
    ValanisLandelDensity vl("liver", c);
    // The density's copies now name the material in their edit errors.
    auto h = *vl.curves().hPrime;
    EXPECT_EQ(messageOf([&] { h.setControlPoint(3, 2.0, -500); }),
              "material 'liver': curve h': control point 3 (x=2, y=-500) does not increase over "
              "point 2 (y=-400)");
}

TEST(ValanisLandel, EditingFPrimeAwayFromRestKeepsTheRestState) {
    // [A §4.3.3, Fig. 4.6]: stiffen the Neo-Hookean material in tension only, keeping f′(1).
    const double mu = 3000, lambda = 30000;
    auto curves = neoHookeanCurves(mu, lambda);
    const ValanisLandelDensity before("nh", curves);
    auto& f = *curves.fPrime;
    // Last point first, so that every single-point edit keeps the values increasing.
    for (std::size_t k = f.size(); k-- > 0;) {
        const auto p = f.controlPoints()[k];
        if (p.x > 1.0 + 1e-9) f.setControlPoint(k, p.x, p.y + 2.0 * mu * (p.x - 1.0));
    }
    const ValanisLandelDensity after("nh_stiff", curves);
    EXPECT_EQ(after.psi(Mat3::Identity()), 0.0);
    EXPECT_LT(after.stress(Mat3::Identity()).norm(), 1e-12 * lambda);
    const Mat3 stretch = Eigen::Vector3d(1.3, 0.9, 0.9).asDiagonal();
    EXPECT_GT(after.psi(stretch), 1.05 * before.psi(stretch));
    EXPECT_GT(after.stress(stretch)(0, 0), 1.2 * before.stress(stretch)(0, 0));
    // Edits are local: a control point's slope depends on its two neighbours each side, so f′ is
    // unchanged below the third point left of the first edited one.
    const double x2 = f.controlPoints()[2].x;
    for (double x : {0.05, 0.1, 0.2, x2})
        EXPECT_DOUBLE_EQ(after.curves().fPrime->value(x), before.curves().fPrime->value(x));
}

TEST(ValanisLandel, PrincipalStressIsTheGradientOfPrincipalEnergy) {
    const ValanisLandelDensity vl("tissue", authoredTissueCurves());
    double worst = 0;
    for (const Eigen::Vector3d& s : {Eigen::Vector3d(1.2, 0.8, 0.6), Eigen::Vector3d(2.5, 1.1, -0.3),
                                     Eigen::Vector3d(0.15, 0.1, 0.04), Eigen::Vector3d(3, 2.5, 2)}) {
        const Eigen::Vector3d d = vl.stressPrincipal(s);
        for (int i = 0; i < 3; ++i) {
            Eigen::Vector3d sp = s, sm = s;
            const double h = 1e-6;
            sp(i) += h;
            sm(i) -= h;
            const double fd = (vl.psiPrincipal(sp) - vl.psiPrincipal(sm)) / (2 * h);
            worst = std::max(worst, std::abs(fd - d(i)) / std::max(1.0, d.norm()));
        }
    }
    EXPECT_LT(worst, 1e-7);
}

TEST(ValanisLandel, NeoHookeanPresetIsAccurateNearRest) {
    // Small strains: the energy is O(ε²), so relative accuracy here depends on the curve slopes
    // at 1, not on the value fit.
    double worst = 0;
    for (const Lame& m : lameSweep()) {
        const ValanisLandelDensity vl("nh", neoHookeanCurves(m.mu, m.lambda));
        for (double eps : {1e-2, 1e-3, 1e-4}) {
            Mat3 shear = Mat3::Identity();
            shear(0, 1) = eps;
            const Mat3 Fs[] = {Mat3(Eigen::Vector3d(1 + eps, 1, 1).asDiagonal()), Mat3((1 - eps) * Mat3::Identity()),
                               shear};
            for (const Mat3& F : Fs) {
                const double psi = nhPsi(F, m.mu, m.lambda);
                const Mat3 P = nhStress(F, m.mu, m.lambda);
                const double e1 = std::abs(vl.psi(F) - psi) / psi;
                const double e2 = (vl.stress(F) - P).norm() / P.norm();
                worst = std::max({worst, e1, e2});
                EXPECT_LT(e1, 1e-6) << "nu=" << m.poisson << " eps=" << eps << "\n" << F;
                EXPECT_LT(e2, 1e-6) << "nu=" << m.poisson << " eps=" << eps << "\n" << F;
            }
        }
    }
    RecordProperty("vl_nh_near_rest_max_rel", sci(worst));
}
