// signedSvd() (direct eigen-decomposition of FᵀF) on degenerate and near-degenerate F, against
// Eigen's Jacobi SVD (the method it replaced), and the Valanis–Landel stress built on it.
#include "material_test_support.hpp"

#include "sim/material/energy_constraint.hpp"
#include "sim/material/laws.hpp"
#include "sim/material/valanis_landel.hpp"

#include <gtest/gtest.h>

#include <Eigen/SVD>

#include <limits>

using namespace viscera::sim;
using namespace viscera::sim::testing;

namespace {

/// The rotation-variant SVD by Eigen's two-sided Jacobi SVD, the reflection moved to σ3: the
/// reference (and the library's method before the direct solver).
SignedSvd jacobiSignedSvd(const Mat3& F) {
    Eigen::JacobiSVD<Mat3> svd(F, Eigen::ComputeFullU | Eigen::ComputeFullV);
    SignedSvd out{svd.matrixU(), svd.singularValues(), svd.matrixV()};
    if (out.U.determinant() < 0) {
        out.U.col(2) *= -1.0;
        out.sigma(2) *= -1.0;
    }
    if (out.V.determinant() < 0) {
        out.V.col(2) *= -1.0;
        out.sigma(2) *= -1.0;
    }
    return out;
}

struct Case {
    std::string label;
    Mat3 F;
    /// The Valanis–Landel stress is not a function of F here, so only Ψ is compared: at an
    /// inverted tie |σ3| = σ2, σ3 < 0 (which of the two carries the sign), and at rank ≤ 1
    /// (U Vᵀ is not unique on the null space).
    bool stressNotUnique = false;
};

Mat3 diag(double a, double b, double c) {
    return Eigen::Vector3d(a, b, c).asDiagonal();
}

/// Degenerate and near-degenerate deformation gradients: repeated, nearly repeated and zero
/// singular values, inverted ones, near-identity states, exact and rotated.
std::vector<Case> degenerateCases() {
    std::mt19937 rng(17);
    std::normal_distribution<double> n(0.0, 1.0);
    const auto gaussian = [&] {
        Mat3 G;
        for (int i = 0; i < 9; ++i)
            G(i) = n(rng);
        return G;
    };
    std::vector<Case> out{
        {"identity", Mat3::Identity()},
        {"minus identity", -Mat3::Identity(), true},
        {"reflection z", diag(1, 1, -1), true},
        {"inverted tie", diag(2, 1, -1), true},
        {"distinct", diag(3, 2, 1)},
        {"unsorted", diag(1, 3, 2)},
        {"unsorted inverted", diag(-0.5, 3, 2)},
        {"zero", Mat3::Zero(), true},
        {"rank 1 axis", diag(1, 0, 0), true},
        {"rank 2 equal", diag(1, 1, 0)},
        {"rank 2", diag(2, 1, 0)},
        {"needle", diag(50, 1e-8, 1e-8)},
        {"uniform stretch", 40.0 * Mat3::Identity()},
        {"uniform compression", 0.01 * Mat3::Identity()},
        {"permutation odd", (Mat3() << 0, 1, 0, 1, 0, 0, 0, 0, 1).finished(), true},
        {"permutation even", (Mat3() << 0, 1, 0, 0, 0, 1, 1, 0, 0).finished()},
        {"rank 1 outer", Eigen::Vector3d(1, -2, 0.5) * Eigen::Vector3d(0.3, 0.2, -1).transpose(), true},
    };
    const std::vector<std::pair<std::string, Eigen::Vector3d>> spectra{
        {"isotropic", {1.3, 1.3, 1.3}},
        {"uniaxial stretch", {1.5, 1, 1}},
        {"uniaxial compression", {0.6, 1, 1}},
        {"repeated pair", {2, 2, 0.5}},
        {"pair 1e-4", {1, 1 + 1e-4, 0.7}},
        {"pair 1e-8", {1, 1 + 1e-8, 0.7}},
        {"pair 1e-12", {1, 1 + 1e-12, 0.7}},
        {"pair 1e-15", {1, 1 + 1e-15, 0.7}},
        {"cluster 1e-8", {1, 1 + 1e-8, 1 - 1e-8}},
        {"cluster 1e-14", {1, 1 + 1e-14, 1 - 2e-14}},
        {"inverted", {1.2, 0.9, -0.4}},
        {"inverted pair", {1, 1, -0.3}},
        {"inverted tie", {1.5, 0.8, -0.8}},
        {"inverted near tie", {1.5, 0.8, -0.8 + 1e-9}},
        {"flat", {1, 0.9, 1e-10}},
        {"flat inverted", {1, 0.9, -1e-10}},
        {"flat pair", {1, 1, 0}},
        {"rank 1", {2, 0, 0}},
        {"anisotropic", {100, 1, 0.01}},
        {"anisotropic inverted", {100, 1, -0.01}},
    };
    for (const auto& [label, s] : spectra)
        for (int k = 0; k < 4; ++k)
            out.push_back({"rotated " + label, randomRotation(rng) * s.asDiagonal() * randomRotation(rng).transpose(),
                           (s(2) < 0 && std::abs(std::abs(s(2)) - s(1)) < 1e-6 * s(1)) || s(1) == 0});
    for (double eps : {1e-4, 1e-8, 1e-12, 1e-15})
        for (int k = 0; k < 4; ++k)
            out.push_back({"near identity " + sci(eps), Mat3(Mat3::Identity() + eps * gaussian())});
    for (int k = 0; k < 4; ++k) {
        const Eigen::Matrix<double, 3, 2> a = Eigen::Matrix<double, 3, 2>::Random();
        const Eigen::Matrix<double, 2, 3> b = Eigen::Matrix<double, 2, 3>::Random();
        out.push_back({"random rank 2", a * b});
    }
    return out;
}

/// Random F with singular values spread over [1e-3, 1e2], every fourth inverted.
std::vector<Mat3> randomSweep(int count, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> logS(-3.0, 2.0);
    std::vector<Mat3> out;
    for (int i = 0; i < count; ++i) {
        Eigen::Vector3d s(std::pow(10.0, logS(rng)), std::pow(10.0, logS(rng)), std::pow(10.0, logS(rng)));
        if (i % 4 == 3) s(2) = -s(2);
        out.push_back(randomRotation(rng) * s.asDiagonal() * randomRotation(rng).transpose());
    }
    return out;
}

/// The contract of signedSvd(), and σ against the Jacobi reference; returns the largest
/// error, relative to max|σ| (or to 1 for F = 0).
double checkSignedSvd(const Mat3& F, const std::string& label) {
    const SignedSvd s = signedSvd(F);
    const double scale = std::max(std::abs(s.sigma(0)), std::numeric_limits<double>::min());
    EXPECT_TRUE(s.U.allFinite() && s.V.allFinite() && s.sigma.allFinite()) << label;
    const double orthoU = (s.U.transpose() * s.U - Mat3::Identity()).norm();
    const double orthoV = (s.V.transpose() * s.V - Mat3::Identity()).norm();
    const double recon = ((s.U * s.sigma.asDiagonal() * s.V.transpose() - F) / scale).norm();
    EXPECT_LT(orthoU, 1e-14) << label;
    EXPECT_LT(orthoV, 1e-14) << label;
    EXPECT_NEAR(s.U.determinant(), 1.0, 1e-14) << label;
    EXPECT_NEAR(s.V.determinant(), 1.0, 1e-14) << label;
    EXPECT_LT(recon, 1e-14) << label << "\n" << F;
    EXPECT_GE(s.sigma(0), s.sigma(1)) << label;
    EXPECT_GE(s.sigma(1), std::abs(s.sigma(2))) << label;
    const double det = F.determinant();
    if (std::abs(det) > 1e-9 * std::pow(scale, 3)) {
        EXPECT_EQ(s.sigma(2) < 0, det < 0) << label;
    }
    const double sigmaErr = (s.sigma - jacobiSignedSvd(F).sigma).cwiseAbs().maxCoeff() / scale;
    EXPECT_LT(sigmaErr, 1e-14) << label << "\n" << F;
    return std::max({orthoU, orthoV, recon, sigmaErr});
}

/// Ψ and P of a Valanis–Landel density through the Jacobi reference SVD.
double referencePsi(const ValanisLandelDensity& vl, const Mat3& F, Mat3* P) {
    const SignedSvd s = jacobiSignedSvd(F);
    if (P) *P = s.U * vl.stressPrincipal(s.sigma).asDiagonal() * s.V.transpose();
    return vl.psiPrincipal(s.sigma);
}

} // namespace

TEST(SignedSvd, DegenerateAndNearDegenerateCasesMatchJacobiSvd) {
    double worst = 0;
    for (const Case& c : degenerateCases())
        worst = std::max(worst, checkSignedSvd(c.F, c.label));
    RecordProperty("signed_svd_degenerate_max_err", sci(worst));
}

TEST(SignedSvd, RandomSpectraOverFiveDecadesMatchJacobiSvd) {
    double worst = 0;
    for (const Mat3& F : randomSweep(2000, 23))
        worst = std::max(worst, checkSignedSvd(F, "random"));
    RecordProperty("signed_svd_random_max_err", sci(worst));
}

TEST(SignedSvd, ScalesExactlyWithF) {
    // Outside [2^-60, 2^60] F is rescaled by a power of two (exact): σ(cF) = c σ(F) to rounding.
    std::mt19937 rng(5);
    for (int k = 0; k < 20; ++k) {
        const Mat3 F = randomRotation(rng) * Eigen::Vector3d(1.7, 0.6, -0.2).asDiagonal() * randomRotation(rng);
        const Eigen::Vector3d s = signedSvd(F).sigma;
        for (double c : {1e-300, 1e-200, 1e-30, 1e30, 1e200, 1e300}) {
            const std::string label = "scale " + sci(c);
            checkSignedSvd(c * F, label);
            const Eigen::Vector3d sc = signedSvd(c * F).sigma / c;
            EXPECT_LT((sc - s).norm(), 1e-14 * s.norm()) << label;
        }
    }
}

TEST(SignedSvd, NonFiniteInputGivesNaN) {
    Mat3 F = Mat3::Identity();
    F(1, 2) = std::numeric_limits<double>::quiet_NaN();
    EXPECT_TRUE(signedSvd(F).sigma.hasNaN());
    F(1, 2) = std::numeric_limits<double>::infinity();
    EXPECT_TRUE(signedSvd(F).sigma.hasNaN());
}

TEST(SignedSvd, ValanisLandelMatchesTheJacobiReferenceOnDegenerateStates) {
    // The decomposition is not unique at repeated singular values, but Ψ and P are (an
    // isotropic law has equal principal stresses there), except where Case::stressNotUnique.
    // Errors relative to max(μ + λ, |value|): rounding level, times the conditioning for the
    // needle-like states (σ1/σ3 up to 1e4, where both SVDs resolve σ3 to ~1e-16 σ1 and the
    // volume term amplifies that by (σ1 σ2)² h″).
    const auto cases = degenerateCases();
    double worstPsi = 0, worstP = 0;
    for (const Lame& m : lameSweep()) {
        const double scale = m.mu + m.lambda;
        const ValanisLandelDensity presets[] = {
            {"nh", neoHookeanCurves(m.mu, m.lambda)},
            {"corot", corotatedCurves(m.mu, m.lambda)},
            {"stvk", stVenantKirchhoffCurves(m.mu, m.lambda)},
        };
        for (const auto& vl : presets)
            for (const Case& c : cases) {
                const Eigen::Vector3d sigma = jacobiSignedSvd(c.F).sigma;
                const double conditioning = std::min(1e4, sigma(0) / std::max(std::abs(sigma(2)), 1e-300));
                const double tol = 1e-13 * std::max(100.0, conditioning);
                Mat3 Pref;
                const double psiRef = referencePsi(vl, c.F, &Pref);
                Mat3 P;
                const double psi = vl.psiAndStress(c.F, P);
                const double ePsi = std::abs(psi - psiRef) / std::max(scale, std::abs(psiRef));
                EXPECT_LT(ePsi, tol) << vl.materialName() << " " << c.label;
                worstPsi = std::max(worstPsi, ePsi);
                if (c.stressNotUnique) continue;
                const double eP = (P - Pref).norm() / std::max(scale, Pref.norm());
                EXPECT_LT(eP, tol) << vl.materialName() << " " << c.label << "\n" << c.F;
                worstP = std::max(worstP, eP);
            }
    }
    RecordProperty("vl_vs_jacobi_degenerate_max_rel_psi", sci(worstPsi));
    RecordProperty("vl_vs_jacobi_degenerate_max_rel_P", sci(worstP));
}

TEST(SignedSvd, ValanisLandelStressIsContinuousAcrossRepeatedSingularValues) {
    // Approaching a repeated pair (and the identity) from distinct values, P converges linearly
    // to its value at the tie: |P(δ) − P(0)| / δ stays at the slope measured at δ = 1e-4, with
    // no jump from switching between branches of the decomposition.
    const ValanisLandelDensity vl("tissue", authoredTissueCurves());
    std::mt19937 rng(8);
    for (int k = 0; k < 10; ++k) {
        const Mat3 R = randomRotation(rng), S = randomRotation(rng);
        for (const Eigen::Vector3d& base : {Eigen::Vector3d(1.3, 1.3, 0.7), Eigen::Vector3d(1.4, 0.8, 0.8),
                                            Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(0.6, 0.6, 0.6)}) {
            const Mat3 P0 = vl.stress(R * base.asDiagonal() * S.transpose());
            const auto change = [&](double d) {
                const Eigen::Vector3d s = base + Eigen::Vector3d(0, d, -d);
                return (vl.stress(R * s.asDiagonal() * S.transpose()) - P0).norm();
            };
            const double slope = change(1e-4) / 1e-4;
            for (double d : {1e-6, 1e-8, 1e-10, 1e-12})
                EXPECT_LT(change(d), 2.0 * slope * d + 1e-12 * P0.norm() + 1e-9)
                    << "d=" << d << " base " << base.transpose();
        }
    }
}

TEST(SignedSvd, CombinedEvaluationIsBitIdenticalToPsiAndStress) {
    std::vector<Mat3> Fs;
    for (const auto& s : sampleDeformations(6, 41))
        Fs.push_back(s.F);
    for (const Case& c : degenerateCases())
        Fs.push_back(c.F);
    for (const Lame& m : lameSweep())
        for (const auto& d : allDensities(m.mu, m.lambda)) {
            const auto* combined = dynamic_cast<const CombinedEnergyDensity*>(d.density.get());
            ASSERT_NE(combined, nullptr) << d.label;
            for (const Mat3& F : Fs) {
                Mat3 P;
                const double psi = combined->psiAndStress(F, P);
                EXPECT_EQ(psi, d.density->psi(F)) << d.label;
                EXPECT_EQ(P, d.density->stress(F)) << d.label;
            }
        }
}
