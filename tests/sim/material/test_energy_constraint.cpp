#include "material_test_support.hpp"

#include "sim/material/energy_constraint.hpp"
#include "sim/material/stable_neo_hookean.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <map>

using namespace viscera::sim;
using namespace viscera::sim::testing;

namespace {

/// Max over constraints k of the relative central-difference error of ∂C_k/∂F.
double constraintGradientError(const TetConstraintModel& model, const Mat3& F) {
    TetConstraintValues v;
    model.evaluate(F, v);
    double worst = 0;
    for (int k = 0; k < v.count; ++k) {
        const Mat3 fd = centralDifference(
            [&](const Mat3& G) {
                TetConstraintValues w;
                model.evaluate(G, w);
                return w.C[k];
            },
            F);
        worst = std::max(worst, relativeGradientError(v.dCdF[k], fd, 1.0));
    }
    return worst;
}

} // namespace

TEST(EnergyConstraint, ConstraintGradientsMatchCentralDifferences) {
    std::map<std::string, double> worst;
    const auto samples = sampleDeformations(12, 99);
    int cases = 0;
    for (const Lame& m : lameSweep()) {
        const StableNeoHookeanModel snh(m.mu, m.lambda);
        for (const auto& s : samples) {
            const double e = constraintGradientError(snh, s.F);
            worst["stable_neo_hookean"] = std::max(worst["stable_neo_hookean"], e);
            EXPECT_LT(e, 1e-6) << "stable_neo_hookean nu=" << m.poisson << " " << s.kind;
            ++cases;
        }
        for (const auto& d : allDensities(m.mu, m.lambda)) {
            const EnergyConstraintModel model(d.density);
            for (const auto& s : samples) {
                const double e = constraintGradientError(model, s.F);
                worst["energy:" + d.label] = std::max(worst["energy:" + d.label], e);
                EXPECT_LT(e, 1e-6) << d.label << " nu=" << m.poisson << " " << s.kind;
                ++cases;
            }
        }
    }
    EXPECT_EQ(cases, 12 * 9 * 48);
    for (const auto& [label, e] : worst)
        RecordProperty("dCdF_fd_max_rel_" + label, sci(e));
}

TEST(EnergyConstraint, ModelEnergyAndGradientAreTheDensity) {
    const auto samples = sampleDeformations(5, 8);
    for (const Lame& m : lameSweep())
        for (const auto& d : allDensities(m.mu, m.lambda)) {
            const EnergyConstraintModel model(d.density);
            EXPECT_EQ(model.count(), 1);
            EXPECT_EQ(model.compliance()[0], 1.0);
            EXPECT_EQ(model.restStiffness(), d.density->restStiffness());
            EXPECT_EQ(model.name(), "energy:" + d.density->name());
            for (const auto& s : samples) {
                const double psi = d.density->psi(s.F);
                TetConstraintValues v;
                model.evaluate(s.F, v);
                EXPECT_NEAR(0.5 * v.C[0] * v.C[0], psi, 1e-12 * psi);
                EXPECT_NEAR(model.energyDensity(s.F), psi, 1e-12 * psi);
                const Mat3 P = d.density->stress(s.F);
                EXPECT_LT((model.energyDensityGradient(s.F) - P).norm(), 1e-12 * P.norm()) << d.label;
            }
        }
}

TEST(EnergyConstraint, RestReportsZeroConstraintAndGradient) {
    for (const auto& d : allDensities(1e4, 4e4)) {
        const EnergyConstraintModel model(d.density);
        TetConstraintValues v;
        v.C[0] = 7;
        v.dCdF[0].setOnes();
        model.evaluate(Mat3::Identity(), v);
        EXPECT_EQ(v.count, 1);
        EXPECT_EQ(v.C[0], 0.0) << d.label;
        EXPECT_EQ(v.dCdF[0], Mat3::Zero()) << d.label;
        // A strain of 1e-4 is well above the rest tolerance: C > 0 and finite gradient.
        const Mat3 F = Eigen::Vector3d(1.0001, 1, 1).asDiagonal();
        model.evaluate(F, v);
        EXPECT_GT(v.C[0], 0.0) << d.label;
        EXPECT_TRUE(v.dCdF[0].allFinite());
        EXPECT_NEAR(0.5 * v.C[0] * v.C[0], d.density->psi(F), 1e-12 * d.density->psi(F));
    }
    EXPECT_THROW(EnergyConstraintModel(nullptr), std::invalid_argument);
}

TEST(EnergyConstraint, InvertedElementsGiveFiniteConstraints) {
    const std::vector<Mat3> Fs{Eigen::Vector3d(1, 1, -1).asDiagonal(), Mat3::Zero(),
                               Eigen::Vector3d(2, 0.5, -0.01).asDiagonal(), Eigen::Vector3d(1, 1, 0).asDiagonal()};
    for (const Lame& m : lameSweep())
        for (const auto& d : allDensities(m.mu, m.lambda)) {
            const EnergyConstraintModel model(d.density);
            for (const Mat3& F : Fs) {
                TetConstraintValues v;
                model.evaluate(F, v);
                EXPECT_TRUE(std::isfinite(v.C[0]) && v.dCdF[0].allFinite()) << d.label << "\n" << F;
            }
        }
}
