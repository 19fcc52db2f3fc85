// Skeleton → tet-node map [A §4.3.5]: Π_j against a brute-force evaluation of the thesis rule,
// r_j, 100 % coverage, the fallback projection, graph figures and input validation.
#include "sim/mesh/generators.hpp"
#include "sim/skeleton/skeleton.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

using namespace viscera::sim;
using ::testing::HasSubstr;

namespace {

/// Box along x (0.1 × 0.02 × 0.02 m) and a straight skeleton of `m` nodes on its centre line;
/// every boundary node corresponds to the skeleton node nearest in x (what an MCF skeleton of a
/// bar gives).
struct Bar {
    std::unique_ptr<TetMesh> mesh;
    Skeleton skeleton;
};

Bar makeBar(int m, std::array<int, 3> cells = {20, 4, 4}) {
    Bar b;
    b.mesh = makeBoxTetMesh({Vec3(0, -0.01, -0.01), Vec3(0.1, 0.02, 0.02), cells});
    b.mesh->requireLevel(2);
    for (int j = 0; j < m; ++j)
        b.skeleton.nodes.emplace_back(0.1 * (j + 0.5) / m, 0, 0);
    for (int j = 0; j + 1 < m; ++j)
        b.skeleton.edges.push_back({j, j + 1});
    b.skeleton.vertexNode.assign(b.mesh->vertexCount(), kNone);
    for (size_t i = 0; i < b.mesh->vertexCount(); ++i) {
        if (!b.mesh->isBoundaryVertex(static_cast<int32_t>(i))) continue;
        const double x = b.mesh->positions()[i].x();
        b.skeleton.vertexNode[i] = std::clamp(static_cast<int32_t>(std::floor(x / 0.1 * m)), 0, m - 1);
    }
    return b;
}

/// The thesis rule evaluated directly: Π_j = corr(j) ∪ {i : |x_i − p_j| <= max_{k∈corr(j)} |x_k − p_j|}.
std::vector<std::set<int32_t>> bruteForcePi(const std::vector<Vec3>& x, const Skeleton& s, std::vector<double>& r) {
    const size_t m = s.nodes.size();
    r.assign(m, 0.0);
    for (size_t i = 0; i < x.size(); ++i)
        if (s.vertexNode[i] >= 0)
            r[s.vertexNode[i]] = std::max(r[s.vertexNode[i]], (x[i] - s.nodes[s.vertexNode[i]]).norm());
    std::vector<std::set<int32_t>> pi(m);
    for (size_t j = 0; j < m; ++j)
        for (size_t i = 0; i < x.size(); ++i)
            if ((x[i] - s.nodes[j]).norm() <= r[j] || s.vertexNode[i] == static_cast<int32_t>(j))
                pi[j].insert(static_cast<int32_t>(i));
    return pi;
}

std::string invalid(const Skeleton& s, size_t n) {
    try {
        validateSkeleton(s, n, "vessel");
    } catch (const std::invalid_argument& e) {
        return e.what();
    }
    return "no error";
}

} // namespace

TEST(SkeletonMap, MatchesTheThesisRuleAndCoversEveryNode) {
    for (int m : {1, 3, 10, 40}) {
        Bar b = makeBar(m);
        const auto& x = b.mesh->positions();
        const SkeletonNodeMap map = mapNodesToSkeleton(*b.mesh, b.skeleton);
        std::vector<double> r;
        const auto pi = bruteForcePi(x, b.skeleton, r);
        ASSERT_EQ(map.skeletonNodeCount(), static_cast<size_t>(m));
        ASSERT_EQ(map.start.size(), static_cast<size_t>(m + 1));
        std::set<int32_t> fallback(map.fallbackNodes.begin(), map.fallbackNodes.end());
        for (int j = 0; j < m; ++j) {
            EXPECT_EQ(map.radius[j], r[j]) << "m " << m << " node " << j;
            std::vector<int32_t> got(map.members.begin() + map.start[j], map.members.begin() + map.start[j + 1]);
            EXPECT_TRUE(std::is_sorted(got.begin(), got.end()));
            // Π_j = thesis rule ∪ the fallback nodes given to j.
            std::set<int32_t> expected = pi[j];
            for (size_t k = 0; k < map.fallbackNodes.size(); ++k)
                if (map.fallbackNode[k] == j) expected.insert(map.fallbackNodes[k]);
            EXPECT_EQ(std::set<int32_t>(got.begin(), got.end()), expected) << "m " << m << " node " << j;
        }
        // The fallback nodes are exactly those that no ball reaches.
        for (size_t i = 0; i < x.size(); ++i) {
            bool reached = false;
            for (int j = 0; j < m; ++j)
                reached |= pi[j].count(static_cast<int32_t>(i)) > 0;
            EXPECT_EQ(fallback.count(static_cast<int32_t>(i)) > 0, !reached) << "node " << i;
        }
        EXPECT_EQ(map.coveredCount(), x.size()) << "coverage must be 100 %";
        EXPECT_EQ(map.meshNodeCount, x.size());
    }
}

TEST(SkeletonMap, FallbackProjectsOnTheSkeletonCurve) {
    // Two skeleton nodes whose balls are tiny (each has one correspondence very close to it):
    // almost every node needs the fallback, which must pick the nearer end of the closest segment.
    Bar b = makeBar(2, {10, 2, 2});
    Skeleton& s = b.skeleton;
    s.nodes = {Vec3(0.02, 0, 0), Vec3(0.08, 0, 0), Vec3(0.05, 0.5, 0)}; // node 2: isolated, far away
    s.edges = {{0, 1}};
    std::fill(s.vertexNode.begin(), s.vertexNode.end(), kNone);
    const auto& x = b.mesh->positions();
    // The two nodes nearest to p_0 and p_1 are their only correspondences.
    for (int j = 0; j < 2; ++j) {
        size_t best = 0;
        for (size_t i = 1; i < x.size(); ++i)
            if ((x[i] - s.nodes[j]).norm() < (x[best] - s.nodes[j]).norm()) best = i;
        s.vertexNode[best] = j;
    }
    const SkeletonNodeMap map = mapNodesToSkeleton(x, s);
    EXPECT_GT(map.fallbackNodes.size(), x.size() / 2);
    EXPECT_EQ(map.coveredCount(), x.size());
    for (size_t k = 0; k < map.fallbackNodes.size(); ++k) {
        const Vec3& p = x[map.fallbackNodes[k]];
        // Brute force over a dense sampling of the segment: the nearer end of the closest point.
        double bestD = std::numeric_limits<double>::infinity(), bestT = 0;
        for (int q = 0; q <= 100000; ++q) {
            const double t = q / 100000.0;
            const double d = (p - (s.nodes[0] + t * (s.nodes[1] - s.nodes[0]))).norm();
            if (d < bestD) bestD = d, bestT = t;
        }
        if (std::abs(bestT - 0.5) < 1e-4) continue; // on the bisector: either end is right
        EXPECT_EQ(map.fallbackNode[k], bestT < 0.5 ? 0 : 1) << "node " << map.fallbackNodes[k];
    }
    // Node 2 has no correspondence: r_2 = 0 and nothing (no node lies exactly at it).
    EXPECT_EQ(map.radius[2], 0.0);
    EXPECT_EQ(map.start[3] - map.start[2], 0);
}

TEST(SkeletonMap, IsolatedNodesAndRepeatRunsAreBitIdentical) {
    Bar b = makeBar(5);
    b.skeleton.edges.clear(); // only isolated nodes: the fallback uses the nearest node
    std::fill(b.skeleton.vertexNode.begin(), b.skeleton.vertexNode.end(), kNone);
    b.skeleton.vertexNode[0] = 0;
    const SkeletonNodeMap a = mapNodesToSkeleton(*b.mesh, b.skeleton);
    const SkeletonNodeMap c = mapNodesToSkeleton(*b.mesh, b.skeleton);
    EXPECT_EQ(a.members, c.members);
    EXPECT_EQ(a.fallbackNode, c.fallbackNode);
    EXPECT_EQ(a.coveredCount(), b.mesh->vertexCount());
    const auto& x = b.mesh->positions();
    for (size_t k = 0; k < a.fallbackNodes.size(); ++k) {
        const Vec3& p = x[a.fallbackNodes[k]];
        double best = std::numeric_limits<double>::infinity();
        for (const Vec3& q : b.skeleton.nodes)
            best = std::min(best, (p - q).norm());
        EXPECT_EQ((p - b.skeleton.nodes[a.fallbackNode[k]]).norm(), best);
    }
}

TEST(SkeletonMap, GraphFigures) {
    Skeleton s;
    s.nodes.assign(6, Vec3::Zero());
    s.edges = {{0, 1}, {1, 2}, {2, 0}, {3, 4}};
    std::vector<int32_t> comp;
    EXPECT_EQ(s.components(comp), 3); // {0,1,2}, {3,4}, {5}
    EXPECT_EQ(comp[0], comp[2]);
    EXPECT_NE(comp[0], comp[3]);
    EXPECT_EQ(s.cycleRank(), 1);
    EXPECT_EQ(s.degrees(), (std::vector<int32_t>{2, 2, 2, 1, 1, 0}));
}

TEST(SkeletonMap, InvalidSkeletonsAreRejectedNamingTheRule) {
    Skeleton ok;
    ok.nodes = {Vec3::Zero(), Vec3(1, 0, 0)};
    ok.edges = {{0, 1}};
    ok.vertexNode = {0, 1, kNone};
    EXPECT_EQ(invalid(ok, 3), "no error");
    EXPECT_THAT(invalid(ok, 4), HasSubstr("vessel: skeleton has 3 vertex correspondences, the mesh has 4 vertices"));
    Skeleton s = ok;
    s.nodes.clear();
    EXPECT_THAT(invalid(s, 3), HasSubstr("skeleton has no nodes"));
    s = ok;
    s.nodes[1].y() = std::nan("");
    EXPECT_THAT(invalid(s, 3), HasSubstr("skeleton node 1 has a non-finite coordinate"));
    s = ok;
    s.edges.push_back({1, 2});
    EXPECT_THAT(invalid(s, 3), HasSubstr("skeleton edge 1 (1, 2) references a node out of range"));
    s = ok;
    s.edges.push_back({1, 1});
    EXPECT_THAT(invalid(s, 3), HasSubstr("is a self loop"));
    s = ok;
    s.edges.push_back({1, 0});
    EXPECT_THAT(invalid(s, 3), HasSubstr("skeleton edge 1 (1, 0) is repeated"));
    s = ok;
    s.vertexNode[2] = 7;
    EXPECT_THAT(invalid(s, 3), HasSubstr("vertex 2 corresponds to skeleton node 7"));
    s = ok;
    s.vertexNode = {kNone, kNone, kNone};
    EXPECT_THAT(invalid(s, 3), HasSubstr("no vertex corresponds to any skeleton node"));
    // The map validates too, and rejects non-finite positions.
    EXPECT_THROW(mapNodesToSkeleton(std::vector<Vec3>(4, Vec3::Zero()), ok), std::invalid_argument);
    std::vector<Vec3> bad = {Vec3::Zero(), Vec3::Zero(), Vec3(0, 0, INFINITY)};
    try {
        mapNodesToSkeleton(bad, ok, "vessel");
        FAIL() << "no error";
    } catch (const std::invalid_argument& e) {
        EXPECT_THAT(e.what(), HasSubstr("vessel: mesh node 2 has a non-finite coordinate"));
    }
}
