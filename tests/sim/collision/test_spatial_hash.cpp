#include "sim/collision/distance.hpp"
#include "sim/collision/spatial_hash.hpp"
#include "sim/collision/tool_shape.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <random>

using namespace viscera::sim;

namespace {

std::vector<Aabb> randomBoxes(std::mt19937& rng, int n, double extent, double maxSize) {
    std::uniform_real_distribution<double> pos(-extent, extent), size(0, maxSize);
    std::vector<Aabb> boxes(n);
    for (Aabb& b : boxes) {
        b.lo = Vec3(pos(rng), pos(rng), pos(rng));
        b.hi = b.lo + Vec3(size(rng), size(rng), size(rng));
    }
    return boxes;
}

std::vector<int32_t> bruteForce(const std::vector<Aabb>& boxes, const Aabb& q) {
    std::vector<int32_t> out;
    for (size_t i = 0; i < boxes.size(); ++i)
        if (boxes[i].overlaps(q)) out.push_back(static_cast<int32_t>(i));
    return out;
}

} // namespace

TEST(SpatialHash, MatchesBruteForceOverCellSizesAndTables) {
    std::mt19937 rng(7);
    for (double cell : {0.002, 0.01, 0.05}) {
        for (size_t table : {size_t(0), size_t(1), size_t(97)}) {
            const auto boxes = randomBoxes(rng, 400, 0.05, 0.02);
            SpatialHash hash(cell, table);
            hash.build(boxes);
            std::vector<int32_t> got;
            for (int q = 0; q < 200; ++q) {
                const Aabb query = randomBoxes(rng, 1, 0.06, 0.03)[0];
                hash.queryInto(query, got);
                ASSERT_EQ(got, bruteForce(boxes, query)) << "cell " << cell << " table " << table;
            }
        }
    }
}

TEST(SpatialHash, HugeAndNonFiniteBoxes) {
    std::mt19937 rng(3);
    auto boxes = randomBoxes(rng, 50, 0.05, 0.01);
    boxes.push_back({Vec3::Constant(-10), Vec3::Constant(10)}); // far more cells than allowed
    boxes.push_back({Vec3::Constant(std::nan("")), Vec3::Zero()});
    SpatialHash hash(0.001);
    hash.build(boxes);
    std::vector<int32_t> got;
    const Aabb q{Vec3::Constant(-0.01), Vec3::Constant(0.01)};
    hash.queryInto(q, got);
    std::vector<int32_t> expect;
    for (size_t i = 0; i + 1 < boxes.size(); ++i)
        if (boxes[i].overlaps(q)) expect.push_back(static_cast<int32_t>(i));
    EXPECT_EQ(got, expect);
    EXPECT_TRUE(std::binary_search(got.begin(), got.end(), 50));
}

TEST(SpatialHash, RejectsBadCellSize) {
    EXPECT_THROW(SpatialHash(0.0), std::invalid_argument);
    EXPECT_THROW(SpatialHash(-1.0), std::invalid_argument);
}

TEST(Distance, ClosestPointOnTriangleAgainstSampling) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-1, 1);
    for (int trial = 0; trial < 200; ++trial) {
        const Vec3 a(u(rng), u(rng), u(rng)), b(u(rng), u(rng), u(rng)), c(u(rng), u(rng), u(rng));
        const Vec3 p(2 * u(rng), 2 * u(rng), 2 * u(rng));
        const TrianglePoint tp = closestPointOnTriangle(p, a, b, c);
        EXPECT_NEAR(tp.bary.sum(), 1.0, 1e-12);
        EXPECT_LT((tp.bary[0] * a + tp.bary[1] * b + tp.bary[2] * c - tp.point).norm(), 1e-12);
        double best = 1e300;
        for (int i = 0; i <= 60; ++i)
            for (int j = 0; i + j <= 60; ++j) {
                const double s = i / 60.0, t = j / 60.0;
                best = std::min(best, (a + s * (b - a) + t * (c - a) - p).norm());
            }
        EXPECT_LE((tp.point - p).norm(), best + 1e-12);
        EXPECT_GE((tp.point - p).norm(), best - 0.05); // sampling resolution
    }
}

TEST(Distance, SegmentTriangleDistanceAgainstSampling) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-1, 1);
    for (int trial = 0; trial < 100; ++trial) {
        const Vec3 a(u(rng), u(rng), 0.2 * u(rng)), b(u(rng), u(rng), 0.2 * u(rng)), c(u(rng), u(rng), 0.2 * u(rng));
        const Vec3 s0(u(rng), u(rng), u(rng)), s1(u(rng), u(rng), u(rng));
        const SegmentTrianglePair st = closestPointsSegmentTriangle(s0, s1, a, b, c);
        EXPECT_NEAR((st.onSegment - st.onTriangle.point).norm(), st.distance, 1e-12);
        double best = 1e300;
        for (int i = 0; i <= 200; ++i) {
            const Vec3 p = s0 + (i / 200.0) * (s1 - s0);
            best = std::min(best, (closestPointOnTriangle(p, a, b, c).point - p).norm());
        }
        EXPECT_LE(st.distance, best + 1e-12);
        EXPECT_GE(st.distance, best - 0.02);
    }
    // Piercing segment: distance 0 at the crossing point.
    const SegmentTrianglePair p = closestPointsSegmentTriangle(Vec3(0.2, 0.2, -1), Vec3(0.2, 0.2, 1), Vec3(0, 0, 0),
                                                               Vec3(1, 0, 0), Vec3(0, 1, 0));
    EXPECT_EQ(p.distance, 0);
    EXPECT_LT((p.onSegment - Vec3(0.2, 0.2, 0)).norm(), 1e-15);
}

TEST(ToolShape, SignedDistancesPosesAndJaws) {
    ToolShape cap = ToolShape::capsule(0.02, 0.005);
    ToolShape::Pose pose = ToolShape::Pose::Identity();
    pose.linear() = Eigen::AngleAxisd(M_PI / 2, Vec3::UnitZ()).toRotationMatrix();
    pose.translation() = Vec3(0.1, 0, 0);
    cap.setPose(pose);
    // Axis now along world y through (0.1, 0, 0).
    EXPECT_NEAR(cap.signedDistance(Vec3(0.1, 0.01, 0.0)), -0.005, 1e-15);
    EXPECT_NEAR(cap.signedDistance(Vec3(0.11, 0.0, 0.0)), 0.005, 1e-15);
    EXPECT_NEAR(cap.signedDistance(Vec3(0.1, 0.03, 0.0)), 0.005, 1e-15); // beyond the end cap
    const auto bb = cap.bounds(0.001);
    EXPECT_NEAR(bb[0].y(), -0.026, 1e-12);
    EXPECT_NEAR(bb[1].x(), 0.106, 1e-12);
    // Non-finite pose ignored.
    ToolShape::Pose bad = pose;
    bad.translation().x() = std::nan("");
    cap.setPose(bad);
    EXPECT_EQ(cap.pose().translation(), pose.translation());

    ToolShape jaws = ToolShape::jaws(0.02, 0.002, 0.0);
    EXPECT_NEAR(jaws.signedDistance(Vec3(0.01, 0, 0.003)), 0.001, 1e-15);
    jaws.setOpening(M_PI / 3);
    const Vec3 tipUp = 0.02 * Vec3(std::cos(M_PI / 6), 0, std::sin(M_PI / 6));
    EXPECT_NEAR(jaws.signedDistance(tipUp), -0.002, 1e-12);
    EXPECT_GT(jaws.signedDistance(Vec3(0.015, 0, 0)), 0); // between the open jaws

    EXPECT_THROW(ToolShape::sphere(0), std::invalid_argument);
    EXPECT_THROW(ToolShape::jaws(0.02, 0.002, 4.0), std::invalid_argument);
    EXPECT_THAT([] { ToolShape::fromCapsules({}); },
                ::testing::ThrowsMessage<std::invalid_argument>(::testing::HasSubstr("at least one part")));
}

TEST(ToolShape, PoseInterpolation) {
    ToolShape::Pose a = ToolShape::Pose::Identity(), b = ToolShape::Pose::Identity();
    b.linear() = Eigen::AngleAxisd(M_PI / 2, Vec3::UnitZ()).toRotationMatrix();
    b.translation() = Vec3(1, 2, 3);
    const ToolShape::Pose m = interpolatePose(a, b, 0.5);
    EXPECT_LT((m.translation() - Vec3(0.5, 1, 1.5)).norm(), 1e-15);
    EXPECT_NEAR(Eigen::AngleAxisd(m.rotation()).angle(), M_PI / 4, 1e-12);
    EXPECT_TRUE(interpolatePose(a, b, 1.0).isApprox(b, 1e-12));
}
