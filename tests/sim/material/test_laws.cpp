#include "material_test_support.hpp"

#include "sim/material/laws.hpp"
#include "sim/util/error.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <map>

using namespace viscera::sim;
using namespace viscera::sim::testing;
using ::testing::HasSubstr;

namespace {} // namespace

TEST(Laws, TableValuesForUniaxialStretch) {
    // F = diag(2, 1, 1), μ = 3, λ = 5: closed forms of [A Table 4.1].
    const double mu = 3, lambda = 5, l2 = std::log(2.0);
    const Mat3 F = Eigen::Vector3d(2, 1, 1).asDiagonal();
    EXPECT_DOUBLE_EQ(LinearElasticDensity(mu, lambda).psi(F), mu + lambda / 2);
    EXPECT_DOUBLE_EQ(StVenantKirchhoffDensity(mu, lambda).psi(F), 2.25 * mu + 1.125 * lambda);
    EXPECT_NEAR(CorotatedLinearDensity(mu, lambda).psi(F), mu + lambda / 2, 1e-14);
    EXPECT_NEAR(NeoHookeanDensity(mu, lambda).psi(F), 1.5 * mu - mu * l2 + lambda / 2 * l2 * l2, 1e-14);
    // Stresses: P11 of each law.
    EXPECT_DOUBLE_EQ(LinearElasticDensity(mu, lambda).stress(F)(0, 0), 2 * mu + lambda);
    EXPECT_DOUBLE_EQ(StVenantKirchhoffDensity(mu, lambda).stress(F)(0, 0), 2 * (3 * mu + 1.5 * lambda));
    EXPECT_NEAR(CorotatedLinearDensity(mu, lambda).stress(F)(0, 0), 2 * mu + lambda, 1e-14);
    EXPECT_NEAR(NeoHookeanDensity(mu, lambda).stress(F)(0, 0), mu * (2 - 0.5) + lambda * l2 * 0.5, 1e-14);
    EXPECT_NEAR(NeoHookeanDensity(mu, lambda).stress(F)(1, 1), lambda * l2, 1e-14);
}

TEST(Laws, RestStateHasZeroEnergyAndStress) {
    double worstPsi = 0, worstP = 0;
    for (const Lame& m : lameSweep())
        for (const auto& d : allDensities(m.mu, m.lambda)) {
            const double scale = d.density->restStiffness();
            worstPsi = std::max(worstPsi, std::abs(d.density->psi(Mat3::Identity())) / scale);
            worstP = std::max(worstP, d.density->stress(Mat3::Identity()).norm() / scale);
            if (d.label != "vl_authored_tissue") { // VL moduli: 4th-order curve slopes
                EXPECT_NEAR(d.density->restStiffness(), m.lambda + 2 * m.mu, 1e-7 * (m.lambda + 2 * m.mu)) << d.label;
            }
        }
    EXPECT_EQ(worstPsi, 0.0);
    EXPECT_LT(worstP, 1e-12);
    RecordProperty("max_rest_stress_over_stiffness", sci(worstP));
}

TEST(Laws, StressMatchesCentralDifferencesOverParameterSweep) {
    std::map<std::string, double> worst;
    int cases = 0;
    const auto samples = sampleDeformations(12, 2024);
    for (const Lame& m : lameSweep())
        for (const auto& d : allDensities(m.mu, m.lambda))
            for (const auto& s : samples) {
                const Mat3 P = d.density->stress(s.F);
                const Mat3 fd = centralDifference([&](const Mat3& F) { return d.density->psi(F); }, s.F);
                const double err = relativeGradientError(P, fd, d.density->restStiffness());
                worst[d.label] = std::max(worst[d.label], err);
                EXPECT_LT(err, 1e-6) << d.label << " E=" << m.youngs << " nu=" << m.poisson << " " << s.kind << "\n"
                                     << s.F;
                ++cases;
            }
    EXPECT_EQ(cases, 12 * 8 * 48);
    for (const auto& [label, e] : worst)
        RecordProperty("fd_max_rel_" + label, sci(e));
}

TEST(Laws, FrameInvariance) {
    std::mt19937 rng(5);
    const auto samples = sampleDeformations(6, 77);
    double worst = 0;
    for (const Lame& m : lameSweep())
        for (const auto& d : allDensities(m.mu, m.lambda)) {
            if (!d.rotationInvariant) continue;
            for (const auto& s : samples) {
                const Mat3 R = randomRotation(rng);
                const double psi = d.density->psi(s.F), psiR = d.density->psi(R * s.F);
                const Mat3 P = d.density->stress(s.F), PR = d.density->stress(R * s.F);
                const double e1 = std::abs(psiR - psi) / std::max(std::abs(psi), 1e-12 * m.mu);
                const double e2 = (PR - R * P).norm() / std::max(P.norm(), 1e-12 * m.mu);
                worst = std::max({worst, e1, e2});
                EXPECT_LT(e1, 1e-10) << d.label << " " << s.kind;
                EXPECT_LT(e2, 1e-10) << d.label << " " << s.kind;
            }
        }
    RecordProperty("frame_invariance_max_rel", sci(worst));
    // The small-strain law is not rotation invariant [A §4.3.1]: a rigid 30° rotation strains it.
    const Mat3 R = Eigen::AngleAxisd(M_PI / 6, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const double c = std::cos(M_PI / 6) - 1;
    EXPECT_NEAR(LinearElasticDensity(2, 3).psi(R), 2 * 2 * c * c + 1.5 * 4 * c * c, 1e-12);
}

TEST(Laws, InvertedAndDegenerateDeformationsStayFinite) {
    std::vector<Mat3> Fs{Eigen::Vector3d(1, 1, -1).asDiagonal(),
                         Mat3(-Mat3::Identity()),
                         Mat3::Zero(),
                         Eigen::Vector3d(1, 0, 0).asDiagonal(),
                         Eigen::Vector3d(2, 0.5, -0.01).asDiagonal(),
                         Mat3(0.01 * Mat3::Identity()),
                         Mat3(-3 * Mat3::Identity()),
                         Eigen::Vector3d(50, 1e-8, 1e-8).asDiagonal(),
                         Mat3(40 * Mat3::Identity()),
                         Eigen::Vector3d(1, 1, 0).asDiagonal()};
    for (const auto& s : sampleDeformations(10, 9))
        if (s.kind == "inverted") Fs.push_back(s.F);
    int checked = 0;
    for (const Lame& m : lameSweep())
        for (const auto& d : allDensities(m.mu, m.lambda))
            for (const Mat3& F : Fs) {
                const double psi = d.density->psi(F);
                const Mat3 P = d.density->stress(F);
                EXPECT_TRUE(std::isfinite(psi)) << d.label << "\n" << F;
                EXPECT_TRUE(P.allFinite()) << d.label << "\n" << F;
                ++checked;
            }
    EXPECT_EQ(checked, 12 * 8 * 20);
}

TEST(Laws, InversionIsPenalizedExceptByStVenantKirchhoff) {
    // Ψ(diag(1, 1, t)) for t from 0.5 down through 0 to −1.
    for (const Lame& m : lameSweep())
        for (const auto& d : allDensities(m.mu, m.lambda)) {
            const auto psiAt = [&](double t) { return d.density->psi(Mat3(Eigen::Vector3d(1, 1, t).asDiagonal())); };
            if (d.label == "st_venant_kirchhoff" || d.label == "vl_st_venant_kirchhoff") {
                // Inversion-blind: the same energy for t and −t.
                for (double t : {0.1, 0.5, 0.9})
                    EXPECT_NEAR(psiAt(-t), psiAt(t), 1e-10 * psiAt(t)) << d.label;
                continue;
            }
            double prev = psiAt(0.5);
            for (int k = 1; k <= 150; ++k) {
                const double t = 0.5 - 1.5 * k / 150.0;
                const double v = psiAt(t);
                EXPECT_GT(v, prev) << d.label << " t=" << t;
                prev = v;
            }
        }
}

TEST(Laws, NeoHookeanLogExtensionIsC2AtJMin) {
    const double mu = 1e4, lambda = 2e5;
    NeoHookeanDensity nh(mu, lambda, 0.05);
    const auto psiAt = [&](double t) { return nh.psi(Mat3(Eigen::Vector3d(1, 1, t).asDiagonal())); };
    const auto p33 = [&](double t) { return nh.stress(Mat3(Eigen::Vector3d(1, 1, t).asDiagonal()))(2, 2); };
    // C0 of Ψ and P33 across J = jMin: the change over [j − e, j + e] is slope · 2e, no jump.
    const double e = 1e-7, j = 0.05;
    const double dP = (p33(j + 1e-4) - p33(j - 1e-4)) / 2e-4; // ≈ μ + φ″(jMin)
    EXPECT_NEAR(psiAt(j - e), psiAt(j + e), 2.01 * e * std::abs(p33(j)));
    EXPECT_NEAR(p33(j - e), p33(j + e), 2.01 * e * std::abs(dP));
    // Second derivative continuous: one-sided slopes of P33 agree.
    const double h = 1e-5;
    const double left = (p33(j) - p33(j - h)) / h, right = (p33(j + h) - p33(j)) / h;
    EXPECT_NEAR(left, right, 1e-3 * std::abs(left));
    // Above jMin it is the plain law: P = μ(F − F⁻ᵀ) + λ log J F⁻ᵀ.
    const Mat3 F = Eigen::Vector3d(1.2, 0.7, 0.3).asDiagonal();
    const Mat3 Finv = F.inverse().transpose();
    const Mat3 P = mu * (F - Finv) + lambda * std::log(F.determinant()) * Finv;
    EXPECT_LT((nh.stress(F) - P).norm(), 1e-12 * P.norm());
}

TEST(Laws, FactoriesAndParameterChecks) {
    for (const char* name : {"linear", "st_venant_kirchhoff", "corotated", "neo_hookean"}) {
        auto d = makeEnergyDensity(name, 1000, 4000);
        EXPECT_EQ(d->name(), name);
        EXPECT_DOUBLE_EQ(d->restStiffness(), 6000);
    }
    EXPECT_EQ(messageOf([] { makeEnergyDensity("mooney_rivlin", 1, 1); }),
              "unknown energy density 'mooney_rivlin' (supported: linear, st_venant_kirchhoff, "
              "corotated, neo_hookean)");
    EXPECT_THROW(makeEnergyDensity("bogus", 1, 1), viscera::InputError);
    EXPECT_EQ(messageOf([] { valanisLandelCurves("linear", 1, 1); }),
              "energy density 'linear' has no Valanis-Landel form (it is not rotation invariant)");
    EXPECT_THROW(valanisLandelCurves("bogus", 1, 1), viscera::InputError);
    EXPECT_THAT(messageOf([] { NeoHookeanDensity(0, 1); }),
                HasSubstr("sim::NeoHookeanDensity(): mu 0 and lambda 1 must be finite"));
    EXPECT_THROW(LinearElasticDensity(1, -1), std::invalid_argument);
    EXPECT_THROW(CorotatedLinearDensity(NAN, 1), std::invalid_argument);
    EXPECT_THROW(StVenantKirchhoffDensity(1, INFINITY), std::invalid_argument);
    EXPECT_THROW(NeoHookeanDensity(1, 1, 1.0), std::invalid_argument);
    EXPECT_NO_THROW(NeoHookeanDensity(1, 0)); // ν = 0
}

TEST(Laws, ValanisLandelFormsMatchTheAnalyticLaws) {
    // StVK and corotated: the VL curves are polynomials reproduced exactly, so both forms agree
    // to rounding, inverted F included. (Neo-Hookean: test_valanis_landel.cpp.)
    const auto samples = sampleDeformations(15, 31);
    double worst = 0;
    for (const Lame& m : lameSweep()) {
        const StVenantKirchhoffDensity stvk(m.mu, m.lambda);
        const CorotatedLinearDensity corot(m.mu, m.lambda);
        const ValanisLandelDensity vlStvk("stvk", stVenantKirchhoffCurves(m.mu, m.lambda));
        const ValanisLandelDensity vlCorot("corot", corotatedCurves(m.mu, m.lambda));
        for (const auto& s : samples) {
            const std::pair<const EnergyDensity*, const EnergyDensity*> pairs[] = {{&stvk, &vlStvk},
                                                                                   {&corot, &vlCorot}};
            for (const auto& [a, b] : pairs) {
                const double scale = m.mu + m.lambda;
                const double ePsi = std::abs(a->psi(s.F) - b->psi(s.F)) / std::max(scale, std::abs(a->psi(s.F)));
                const double eP = (a->stress(s.F) - b->stress(s.F)).norm() / std::max(scale, a->stress(s.F).norm());
                worst = std::max({worst, ePsi, eP});
                EXPECT_LT(ePsi, 1e-11) << a->name() << " " << s.kind;
                EXPECT_LT(eP, 1e-11) << a->name() << " " << s.kind;
            }
        }
        EXPECT_NEAR(vlStvk.shearModulus(), m.mu, 1e-9 * m.mu);
        EXPECT_NEAR(vlStvk.lameLambda(), m.lambda, 1e-9 * (m.mu + m.lambda));
        EXPECT_NEAR(vlCorot.shearModulus(), m.mu, 1e-9 * m.mu);
        EXPECT_NEAR(vlCorot.lameLambda(), m.lambda, 1e-9 * (m.mu + m.lambda));
    }
    RecordProperty("vl_vs_analytic_stvk_corotated_max_rel", sci(worst));
}
