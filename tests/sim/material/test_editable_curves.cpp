#include "material_test_support.hpp"

#include "sim/material/editable_curves.hpp"
#include "sim/material/laws.hpp"
#include "sim/material/material_response.hpp"
#include "sim/util/error.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

using namespace viscera::sim;
using namespace viscera::sim::testing;
using ::testing::HasSubstr;

namespace {

const char* const kLaws[] = {"neo_hookean", "st_venant_kirchhoff", "corotated"};

void expectEditable(const std::optional<MonotoneCurve>& c, double xmin, double xmax, const std::string& what) {
    ASSERT_TRUE(c) << what;
    const auto& pts = c->controlPoints();
    EXPECT_GE(pts.size(), 7u) << what;
    EXPECT_LE(pts.size(), 15u) << what;
    EXPECT_EQ(pts.front().x, xmin) << what;
    EXPECT_EQ(pts.back().x, xmax) << what;
    EXPECT_EQ(std::count_if(pts.begin(), pts.end(), [](const CurvePoint& p) { return p.x == 1.0; }), 1) << what;
}

} // namespace

TEST(EditableCurves, FewPointsWithARestPointOverTheTissueRange) {
    for (const Lame& p : lameSweep()) {
        for (const char* law : kLaws) {
            const std::string what =
                std::string(law) + " E=" + std::to_string(p.youngs) + " nu=" + std::to_string(p.poisson);
            const ValanisLandelCurves c = editableCurves(law, p.youngs, p.poisson);
            expectEditable(c.fPrime, 0.3, 3.0, what + " f'");
            if (c.gPrime) expectEditable(c.gPrime, 0.3, 3.0, what + " g'");
            if (c.hPrime) expectEditable(c.hPrime, 0.3, 2.5, what + " h'");
            const RestNormalization rest = restNormalization(c);
            EXPECT_EQ(rest.restEnergy, 0.0) << what;
            EXPECT_TRUE(rest.balanced) << what;
            EXPECT_LE(std::abs(rest.restStress), rest.restStressTolerance) << what;
            EXPECT_NO_THROW(ValanisLandelDensity(law, c)) << what;
        }
        // The Neo-Hookean preset is eq. 4.19–4.20 at its points, both curves strictly increasing.
        const ValanisLandelCurves nh = editableCurves("neo_hookean", p.youngs, p.poisson);
        EXPECT_FALSE(nh.gPrime);
        EXPECT_EQ(nh.fPrime->shape(), CurveShape::StrictlyIncreasing);
        EXPECT_EQ(nh.hPrime->shape(), CurveShape::StrictlyIncreasing);
        for (const CurvePoint& q : nh.fPrime->controlPoints())
            EXPECT_DOUBLE_EQ(q.y, p.mu * q.x);
        for (const CurvePoint& q : nh.hPrime->controlPoints())
            EXPECT_DOUBLE_EQ(q.y, (p.lambda * std::log(q.x) - p.mu) / q.x);
        EXPECT_EQ(restNormalization(nh).restStress, 0.0); // f′(1) = μ, h′(1) = −μ exactly
        EXPECT_EQ(editableCurves("corotated", p.youngs, p.poisson).gPrime->shape(), CurveShape::Unconstrained);
        EXPECT_EQ(editableCurves("st_venant_kirchhoff", p.youngs, p.poisson).fPrime->shape(),
                  CurveShape::Unconstrained);
    }
    // λ = 0 (ν = 0): no g′ for the two laws that have one.
    EXPECT_FALSE(editableCurves("corotated", 1e3, 0.0).gPrime);
    EXPECT_FALSE(editableCurves("st_venant_kirchhoff", 1e3, 0.0).gPrime);
    EXPECT_EQ(editableCurves("neo_hookean", 1e3, 0.0).hPrime->shape(), CurveShape::StrictlyIncreasing);
}

TEST(EditableCurves, NeoHookeanPresetUniaxialStressWithinOnePercent) {
    // Acceptance (goal < 1 %): the preset's uniaxial response against the analytic law over
    // stretch 0.6–1.6, over the Lamé sweep; largest relative error recorded.
    double worst = 0;
    for (const Lame& p : lameSweep()) {
        const ValanisLandelDensity preset("nh", editableCurves("neo_hookean", p.youngs, p.poisson));
        const NeoHookeanDensity exact(p.mu, p.lambda);
        for (int i = 0; i <= 100; ++i) {
            const double s = 0.6 + 0.01 * i;
            if (std::abs(s - 1.0) < 1e-9) continue;
            const double a = uniaxialNominalStress(exact, s).nominalStress;
            const double e = std::abs(uniaxialNominalStress(preset, s).nominalStress - a) / std::abs(a);
            worst = std::max(worst, e);
            EXPECT_LT(e, 1e-2) << "E=" << p.youngs << " nu=" << p.poisson << " stretch " << s;
        }
    }
    RecordProperty("nh_preset_uniaxial_max_rel_error", sci(worst));
}

TEST(EditableCurves, CubicAndLinearPresetsAreExactInsideTheirRange) {
    for (const Lame& p : lameSweep()) {
        for (const char* law : {"st_venant_kirchhoff", "corotated"}) {
            const ValanisLandelDensity preset(law, editableCurves(law, p.youngs, p.poisson));
            const auto exact = makeEnergyDensity(law, p.mu, p.lambda);
            for (const auto& f : sampleDeformations(3, 11)) {
                const Eigen::Vector3d s = Eigen::JacobiSVD<Mat3>(f.F).singularValues();
                if (f.kind == "inverted" || s.minCoeff() < 0.3 || s.maxCoeff() > 3.0 || s(0) * s(1) > 3.0) continue;
                const Mat3 P = preset.stress(f.F), Q = exact->stress(f.F);
                EXPECT_LT((P - Q).norm(), 1e-9 * (p.lambda + 2 * p.mu) * (1 + f.F.squaredNorm()))
                    << law << " " << f.kind;
            }
        }
    }
}

TEST(EditableCurves, SmallStrainConstantsRoundTrip) {
    double worstNh = 0;
    for (const Lame& p : lameSweep()) {
        for (const char* law : kLaws) {
            const SmallStrainConstants k = smallStrainConstants(editableCurves(law, p.youngs, p.poisson));
            const double eE = std::abs(k.youngsModulus - p.youngs) / p.youngs;
            const double eNu = std::abs(k.poissonRatio - p.poisson);
            EXPECT_NEAR(k.shearModulus, p.mu, 1e-9 * p.mu) << law;
            if (std::string(law) == "neo_hookean") {
                // h″(1) comes from the interpolant's slope at 1 (5-point rule), not exact.
                EXPECT_LT(eE, 1e-3) << law << " E=" << p.youngs << " nu=" << p.poisson;
                EXPECT_LT(eNu, 1e-3) << law << " E=" << p.youngs << " nu=" << p.poisson;
                worstNh = std::max({worstNh, eE, eNu});
            } else {
                EXPECT_LT(eE, 1e-9) << law;
                EXPECT_LT(eNu, 1e-9) << law;
                EXPECT_NEAR(k.lameLambda, p.lambda, 1e-9 * (p.lambda + p.mu)) << law;
            }
        }
    }
    RecordProperty("nh_preset_E_nu_roundtrip_max_error", sci(worstNh));
}

TEST(EditableCurves, RestNormalizationReportsAnUnbalancedRest) {
    ValanisLandelCurves c = authoredTissueCurves();
    EXPECT_TRUE(restNormalization(c).balanced);
    c.fPrime->setControlPoint(2, 1.0, 250.0); // f′(1) 200 → 250
    const RestNormalization r = restNormalization(c);
    EXPECT_FALSE(r.balanced);
    EXPECT_NEAR(r.restStress, 50.0, 1e-9);
    EXPECT_EQ(r.restEnergy, 0.0);
    EXPECT_GT(r.restStressTolerance, 0.0);
    const RestNormalization none = restNormalization(ValanisLandelCurves{});
    EXPECT_EQ(none.restStress, 0.0);
    EXPECT_TRUE(none.balanced);
}

TEST(EditableCurves, BadInputIsRefusedWithAMessage) {
    EXPECT_THAT(messageOf([] { editableCurves("linear", 1e3, 0.3); }),
                HasSubstr("unknown editable curve preset 'linear' (supported: neo_hookean, st_venant_kirchhoff, "
                          "corotated)"));
    EXPECT_THROW(editableCurves("mooney", 1e3, 0.3), viscera::InputError);
    EXPECT_THAT(messageOf([] { editableCurves("neo_hookean", 1e3, 0.5); }),
                HasSubstr("sim::editableCurves(): poisson_ratio 0.500000 must be in [0, 0.5)"));
    EXPECT_THROW(editableCurves("neo_hookean", -1.0, 0.3), std::invalid_argument);
    ValanisLandelCurves bad = authoredTissueCurves();
    bad.fPrime->setControlPoint(2, 1.0, 250.0);
    EXPECT_THAT(messageOf([&] { smallStrainConstants(bad); }), HasSubstr("stress at rest"));
    EXPECT_THROW(smallStrainConstants(bad), viscera::InputError);
}
