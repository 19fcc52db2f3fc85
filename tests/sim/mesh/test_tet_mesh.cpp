#include "chf_reference.hpp"
#include "sim/mesh/generators.hpp"
#include "sim/mesh/tet_mesh.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <random>

using namespace viscera::sim;
using ::testing::HasSubstr;

namespace {

std::unique_ptr<TetMesh> jitteredBox(std::array<int, 3> cells, double jitter, uint32_t seed) {
    auto box = makeBoxTetMesh({Vec3::Zero(), Vec3(1.0, 0.8, 0.6), cells});
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-jitter, jitter);
    auto pos = box->positions();
    const double h = 0.6 / cells[2];
    for (Vec3& p : pos)
        p += h * Vec3(u(rng), u(rng), u(rng));
    return TetMesh::fromArrays(std::move(pos), box->tets());
}

} // namespace

TEST(TetMesh, ChfMatchesBruteForceSmallBox) {
    auto m = makeBoxTetMesh({Vec3::Zero(), Vec3(1, 1, 1), {2, 2, 2}});
    EXPECT_EQ(m->tetCount(), 48u);
    viscera::sim::testing::expectChfMatchesBruteForce(*m, 1000, 1);
}

TEST(TetMesh, ChfMatchesBruteForceJitteredBox) {
    auto m = jitteredBox({5, 4, 3}, 0.2, 7);
    EXPECT_TRUE(m->quality().inverted.empty());
    viscera::sim::testing::expectChfMatchesBruteForce(*m, 1000, 2);
}

TEST(TetMesh, ChfMatchesBruteForceOver20kTets) {
    auto m = makeBoxTetMesh({Vec3::Zero(), Vec3(0.2, 0.2, 0.1), {20, 20, 10}});
    ASSERT_GT(m->tetCount(), 20000u);
    viscera::sim::testing::expectChfMatchesBruteForce(*m, 150, 3);
}

TEST(TetMesh, LevelsAreExplicit) {
    auto m = makeBoxTetMesh({});
    EXPECT_EQ(m->level(), 1);
    try {
        (void)m->edgeCount();
        FAIL() << "expected a logic_error";
    } catch (const std::logic_error& e) {
        EXPECT_THAT(e.what(), HasSubstr("sim::TetMesh::edgeCount(): requires adjacency level 2"));
        EXPECT_THAT(e.what(), HasSubstr("requireLevel(2)"));
    }
    EXPECT_THROW((void)m->boundary(), std::logic_error);
    m->requireLevel(3);
    EXPECT_EQ(m->level(), 3);
    EXPECT_GT(m->adjacencyBytes(), 0u);
    EXPECT_THROW(m->requireLevel(4), std::invalid_argument);
}

TEST(TetMesh, FromArraysRejectsBadInputWithMessages) {
    std::vector<Vec3> p = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
    auto expectMessage = [](auto&& build, const char* text) {
        try {
            build();
            FAIL() << "expected invalid_argument: " << text;
        } catch (const std::invalid_argument& e) {
            EXPECT_THAT(e.what(), HasSubstr(text));
        }
    };
    expectMessage([&] { TetMesh::fromArrays(p, {}); }, "mesh has no tets");
    expectMessage(
        [&] {
            TetMesh::fromArrays(p, {{0, 1, 2, 9}});
        },
        "sim::TetMesh::fromArrays(): tet 0 references vertex 9 (mesh has 4 vertices)");
    expectMessage([&] { TetMesh::fromArrays(p, {{0, 1, 1, 3}}); }, "tet 0 repeats vertex 1");
    auto bad = p;
    bad[2].y() = std::numeric_limits<double>::quiet_NaN();
    expectMessage([&] { TetMesh::fromArrays(bad, {{0, 1, 2, 3}}); }, "vertex 2 has a non-finite coordinate");
    // Three tets on one facet: non-manifold.
    auto q = p;
    q.push_back(Vec3(0.2, 0.2, -1));
    q.push_back(Vec3(0.3, 0.3, -2));
    expectMessage(
        [&] {
            TetMesh::fromArrays(q, {{0, 1, 2, 3}, {0, 2, 1, 4}, {0, 2, 1, 5}});
        },
        "is shared by 3 tets (non-manifold");
}

TEST(TetMesh, BarycentricCoordinates) {
    auto m = jitteredBox({3, 3, 3}, 0.15, 11);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int32_t t = 0; t < static_cast<int32_t>(m->tetCount()); t += 7) {
        const auto& e = m->tets()[t];
        for (int i = 0; i < 4; ++i) {
            Eigen::Vector4d xi = m->barycentric(t, m->positions()[e[i]]);
            EXPECT_NEAR(xi[i], 1.0, 1e-12);
            EXPECT_NEAR(xi.sum(), 1.0, 1e-12);
        }
        Eigen::Vector4d w(u(rng), u(rng), u(rng), u(rng));
        w /= w.sum();
        Vec3 p = Vec3::Zero();
        for (int i = 0; i < 4; ++i)
            p += w[i] * m->positions()[e[i]];
        EXPECT_LT((m->barycentric(t, p) - w).norm(), 1e-12);
    }
    // Triangle barycentrics, with a point off the plane projected onto it.
    Eigen::Vector3d b = barycentric(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0.25, 0.5, 3));
    EXPECT_NEAR(b[0], 0.25, 1e-15);
    EXPECT_NEAR(b[1], 0.25, 1e-15);
    EXPECT_NEAR(b[2], 0.5, 1e-15);
}

TEST(TetMesh, QualityReportFindsInvertedSliverAndDegenerate) {
    std::vector<Vec3> p = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1),
                           // sliver: four nearly coplanar, well separated points
                           Vec3(2, 0, 0), Vec3(3, 0, 0), Vec3(2.5, 1, 0.01), Vec3(2.5, -1, 0.0),
                           // degenerate: a flat tet
                           Vec3(5, 0, 0), Vec3(6, 0, 0), Vec3(5, 1, 0), Vec3(6, 1, 0)};
    std::vector<Tet> t = {{0, 1, 2, 3}, {0, 2, 1, 3}, {4, 5, 6, 7}, {8, 9, 10, 11}};
    // Make the sliver positively oriented.
    auto m0 = TetMesh::fromArrays(p, {t[2]});
    if (m0->signedVolume(0) < 0) std::swap(t[2][2], t[2][3]);
    auto m = TetMesh::fromArrays(p, t);
    QualityReport q = m->quality();
    EXPECT_EQ(q.inverted, std::vector<int32_t>{1});
    EXPECT_EQ(q.slivers, std::vector<int32_t>{2});
    EXPECT_EQ(q.degenerate, std::vector<int32_t>{3});
    EXPECT_FALSE(q.ok());
    EXPECT_LT(q.minDihedralDeg, 5.0);

    auto good = makeBoxTetMesh({});
    QualityReport g = good->quality();
    EXPECT_TRUE(g.ok());
    EXPECT_NEAR(g.totalVolume, 0.1 * 0.02 * 0.04, 1e-15);
    EXPECT_GT(g.minMeanRatio, 0.1);
    EXPECT_LE(g.meanMeanRatio, 1.0);
}

TEST(TetMesh, RegularTetHasUnitMeanRatio) {
    std::vector<Vec3> p = {Vec3(1, 1, 1), Vec3(1, -1, -1), Vec3(-1, 1, -1), Vec3(-1, -1, 1)};
    auto m = TetMesh::fromArrays(p, {{0, 1, 2, 3}});
    if (m->signedVolume(0) < 0) m = TetMesh::fromArrays(p, {{0, 2, 1, 3}});
    QualityReport q = m->quality();
    EXPECT_NEAR(q.minMeanRatio, 1.0, 1e-12);
    EXPECT_NEAR(q.minDihedralDeg, std::acos(1.0 / 3.0) * 180.0 / std::numbers::pi, 1e-9);
}
