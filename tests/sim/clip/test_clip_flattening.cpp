// Visual flattening [A eq. 5.19]: displacement against the closed form on a straight tube,
// bounds (never across the jaws' mid-plane, nothing beyond the influence radius, no NaN on the
// axis or at the centre), equivariance under rigid motion, input checks.
#include "sim/clip/clip_flattening.hpp"

#include "clip_test_support.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

using namespace viscera::sim;
using namespace viscera::sim::testing;
using ::testing::HasSubstr;

namespace {

const Vec3 kMid(0, 0, 0.03);

std::vector<Vec3> axisPolyline() {
    std::vector<Vec3> p;
    for (int i = 0; i <= 6; ++i)
        p.emplace_back(0, 0, 0.01 * i);
    return p;
}

struct Fixture {
    std::unique_ptr<TetMesh> mesh = clipTube(0.06, 24, 24);
    std::vector<Vec3> render;
    std::unique_ptr<ClipAttachment> clip;
    Fixture() {
        render = mesh->positions();
        render.push_back(kMid);                    // on the axis, at the centre (s = 0, ρ = 0)
        render.emplace_back(0, 0, 0.031);          // on the axis, off centre
        render.emplace_back(0.0001, 0.0025, 0.03); // inside the lumen, at the centre
        clip = ClipAttachment::apply(*mesh, mesh->positions(), clipAcross(kMid, Vec3::UnitZ(), Vec3::UnitY(), 0.003));
    }
};

} // namespace

TEST(ClipFlattening, MatchesClosedFormOnAStraightTube) {
    Fixture fx;
    for (double gamma : {0.5, 1.0, 2.0}) {
        FlattenSettings s;
        s.gamma = gamma;
        s.eta = 3e-3 * std::pow(2e-3, gamma); // f = 3 mm at s = 2 mm before the shift
        s.minDistance = 0.5e-3;
        s.influence = 8e-3;
        s.maxSqueeze = 0.7;
        auto fl = ClipFlattening::create(*fx.clip, fx.render, axisPolyline(), s);
        std::vector<Vec3> out;
        ASSERT_TRUE(fl->flattenInto(*fx.clip, fx.render, out));
        ASSERT_EQ(out.size(), fx.render.size());
        int moved = 0;
        for (size_t i = 0; i < out.size(); ++i) {
            const Vec3& x = fx.render[i];
            ASSERT_TRUE(out[i].allFinite()) << i;
            const double si = std::abs(x.z() - fx.clip->centre().z()), rho = std::hypot(x.x(), x.y());
            Vec3 expect = x;
            if (si < s.influence && rho > 1e-12) {
                const double f =
                    s.eta / std::pow(std::max(si, s.minDistance), gamma) - s.eta / std::pow(s.influence, gamma);
                expect.y() -= std::min(f, s.maxSqueeze * rho) * x.y() / rho;
            }
            EXPECT_LT((out[i] - expect).norm(), 1e-15) << i;
            // Only the y coordinate (jaw normal) changes; never across the mid-plane y = 0.
            EXPECT_EQ(out[i].x(), x.x());
            EXPECT_EQ(out[i].z(), x.z());
            EXPECT_GE(out[i].y() * x.y(), 0.0);
            EXPECT_GE(std::abs(out[i].y()), (1 - s.maxSqueeze) * std::abs(x.y()) - 1e-18);
            if ((out[i] - x).norm() > 1e-6) ++moved;
        }
        EXPECT_GT(moved, 20) << gamma;
        // The top of the outer wall at the clip is squeezed by the cap κ ρ.
        EXPECT_EQ(out[fx.mesh->vertexCount()], fx.render[fx.mesh->vertexCount()]); // on the axis
    }
}

TEST(ClipFlattening, OrderAlongRaysIsKept) {
    // Inner and outer wall vertices of the same slice keep their order (no wall inversion),
    // for a strong factor.
    Fixture fx;
    FlattenSettings s;
    s.eta = 1e-4;
    s.gamma = 2;
    s.minDistance = 1e-4;
    auto fl = ClipFlattening::create(*fx.clip, fx.render, axisPolyline(), s);
    std::vector<Vec3> out;
    fl->flattenInto(*fx.clip, fx.render, out);
    const int ns = 24;
    for (int k = 0; k <= 24; ++k)
        for (int i = 0; i < ns; ++i) {
            const int inner = (k * 2 + 0) * ns + i, outer = (k * 2 + 1) * ns + i;
            EXPECT_LE(std::abs(out[inner].y()), std::abs(out[outer].y()) + 1e-15);
        }
}

TEST(ClipFlattening, FollowsTheClipUnderRigidMotion) {
    Fixture fx;
    FlattenSettings s;
    auto fl = ClipFlattening::create(*fx.clip, fx.render, axisPolyline(), s);
    std::vector<Vec3> out0, out, outExplicit;
    fl->flattenInto(*fx.clip, fx.render, out0);
    const Mat3 M = rotationAbout(Vec3(1, 2, 0.5), 0.9);
    const Vec3 t(0.02, -0.01, 0.015);
    for (int k = 0; k < 10; ++k)
        ASSERT_EQ(fx.clip->update(transformed(fx.mesh->positions(), M, t, kMid)), ClipUpdateStatus::Ok);
    const auto render = transformed(fx.render, M, t, kMid);
    ASSERT_TRUE(fl->flattenInto(*fx.clip, render, out));
    EXPECT_LT(maxDeviation(out, transformed(out0, M, t, kMid)), 1e-9);
    ASSERT_TRUE(fl->flattenInto(*fx.clip, render, transformed(axisPolyline(), M, t, kMid), outExplicit));
    EXPECT_LT(maxDeviation(outExplicit, out), 1e-9);
}

TEST(ClipFlattening, BadInput) {
    Fixture fx;
    auto expectThrow = [&](const std::vector<Vec3>& skel, const FlattenSettings& s, const std::string& text) {
        try {
            ClipFlattening::create(*fx.clip, fx.render, skel, s);
            ADD_FAILURE() << "no throw for " << text;
        } catch (const std::invalid_argument& e) {
            EXPECT_THAT(e.what(), HasSubstr("sim::ClipFlattening::create(): "));
            EXPECT_THAT(e.what(), HasSubstr(text));
        }
    };
    expectThrow({Vec3::Zero()}, {}, "at least 2 points");
    FlattenSettings s;
    s.gamma = 0;
    expectThrow(axisPolyline(), s, "gamma");
    s = {};
    s.influence = s.minDistance;
    expectThrow(axisPolyline(), s, "influence");
    s = {};
    s.maxSqueeze = 1;
    expectThrow(axisPolyline(), s, "maxSqueeze");
    auto skel = axisPolyline();
    skel[2].x() = std::numeric_limits<double>::quiet_NaN();
    expectThrow(skel, {}, "skeleton[2]");

    auto fl = ClipFlattening::create(*fx.clip, fx.render, axisPolyline());
    std::vector<Vec3> out;
    const std::vector<Vec3> shortInput(5, Vec3::Ones());
    EXPECT_FALSE(fl->flattenInto(*fx.clip, shortInput, out));
    EXPECT_EQ(out, shortInput);
    EXPECT_FALSE(fl->flattenInto(*fx.clip, fx.render, std::vector<Vec3>(3, Vec3::Zero()), out));
    EXPECT_EQ(out, fx.render);
    // A non-finite render vertex is passed through untouched, the others are flattened.
    auto bad = fx.render;
    const int32_t victim = fl->candidates()[0];
    bad[victim].y() = std::numeric_limits<double>::quiet_NaN();
    EXPECT_TRUE(fl->flattenInto(*fx.clip, bad, out));
    for (size_t i = 0; i < out.size(); ++i) {
        if (static_cast<int32_t>(i) != victim) {
            EXPECT_TRUE(out[i].allFinite()) << i;
        }
    }
}
