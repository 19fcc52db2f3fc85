#include "sim/skeleton/skeleton.hpp"

#include "sim/collision/distance.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <set>
#include <stdexcept>
#include <utility>

namespace viscera::sim {

std::vector<int32_t> Skeleton::degrees() const {
    std::vector<int32_t> deg(nodes.size(), 0);
    for (const auto& e : edges) {
        ++deg[e[0]];
        ++deg[e[1]];
    }
    return deg;
}

int32_t Skeleton::components(std::vector<int32_t>& componentOfNode) const {
    // Union–find with path halving; components numbered by their lowest node.
    std::vector<int32_t> parent(nodes.size());
    std::iota(parent.begin(), parent.end(), 0);
    auto find = [&](int32_t a) {
        while (parent[a] != a)
            a = parent[a] = parent[parent[a]];
        return a;
    };
    for (const auto& e : edges) {
        const int32_t a = find(e[0]), b = find(e[1]);
        if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
    componentOfNode.assign(nodes.size(), -1);
    std::vector<int32_t> label(nodes.size(), -1);
    int32_t count = 0;
    for (size_t i = 0; i < nodes.size(); ++i) {
        const int32_t r = find(static_cast<int32_t>(i));
        if (label[r] < 0) label[r] = count++;
        componentOfNode[i] = label[r];
    }
    return count;
}

int64_t Skeleton::cycleRank() const {
    std::vector<int32_t> comp;
    const int32_t c = components(comp);
    return static_cast<int64_t>(edges.size()) - static_cast<int64_t>(nodes.size()) + c;
}

void validateSkeleton(const Skeleton& s, size_t vertexCount, const std::string& origin) {
    auto fail = [&](const std::string& rule) { throw std::invalid_argument(origin + ": " + rule); };
    const int64_t m = static_cast<int64_t>(s.nodes.size());
    if (m == 0) fail("skeleton has no nodes");
    for (int64_t j = 0; j < m; ++j)
        if (!s.nodes[j].allFinite()) fail("skeleton node " + std::to_string(j) + " has a non-finite coordinate");
    std::set<std::pair<int32_t, int32_t>> seen;
    for (size_t e = 0; e < s.edges.size(); ++e) {
        const auto [a, b] = s.edges[e];
        const std::string name =
            "skeleton edge " + std::to_string(e) + " (" + std::to_string(a) + ", " + std::to_string(b) + ")";
        if (a < 0 || b < 0 || a >= m || b >= m)
            fail(name + " references a node out of range (skeleton has " + std::to_string(m) + " nodes)");
        if (a == b) fail(name + " is a self loop");
        if (!seen.emplace(std::min(a, b), std::max(a, b)).second) fail(name + " is repeated");
    }
    if (s.vertexNode.size() != vertexCount)
        fail("skeleton has " + std::to_string(s.vertexNode.size()) + " vertex correspondences, the mesh has " +
             std::to_string(vertexCount) + " vertices");
    bool any = false;
    for (size_t i = 0; i < s.vertexNode.size(); ++i) {
        const int32_t j = s.vertexNode[i];
        if (j == kNone) continue;
        if (j < 0 || j >= m)
            fail("vertex " + std::to_string(i) + " corresponds to skeleton node " + std::to_string(j) +
                 " (skeleton has " + std::to_string(m) + " nodes; -1 = none)");
        any = true;
    }
    if (!any) fail("no vertex corresponds to any skeleton node");
}

size_t SkeletonNodeMap::coveredCount() const {
    std::vector<char> covered(meshNodeCount, 0);
    for (int32_t i : members)
        covered[i] = 1;
    return static_cast<size_t>(std::count(covered.begin(), covered.end(), 1));
}

namespace {

/// Skeleton node nearest to the projection of p on the skeleton: the closest point over all edges
/// (as segments) and all isolated nodes, then the nearer end of the winning segment. Ties go to
/// the first edge / lower node index, so the result is deterministic.
int32_t projectOnSkeleton(const Vec3& p, const Skeleton& s, const std::vector<int32_t>& degree) {
    double best = std::numeric_limits<double>::infinity();
    int32_t bestNode = 0;
    for (const auto& [a, b] : s.edges) {
        const Vec3& pa = s.nodes[a];
        const Vec3& pb = s.nodes[b];
        const double t = closestParameterOnSegment(p, pa, pb);
        const double d = (p - (pa + t * (pb - pa))).squaredNorm();
        if (d < best) {
            best = d;
            const int32_t lo = std::min(a, b), hi = std::max(a, b);
            const double tLo = lo == a ? t : 1.0 - t; // parameter measured from the lower node
            bestNode = tLo <= 0.5 ? lo : hi;
        }
    }
    for (size_t j = 0; j < s.nodes.size(); ++j) {
        if (degree[j] != 0) continue;
        const double d = (p - s.nodes[j]).squaredNorm();
        if (d < best) {
            best = d;
            bestNode = static_cast<int32_t>(j);
        }
    }
    return bestNode;
}

} // namespace

SkeletonNodeMap mapNodesToSkeleton(const std::vector<Vec3>& positions, const Skeleton& s, const std::string& origin) {
    validateSkeleton(s, positions.size(), origin);
    for (size_t i = 0; i < positions.size(); ++i)
        if (!positions[i].allFinite())
            throw std::invalid_argument(origin + ": mesh node " + std::to_string(i) + " has a non-finite coordinate");

    const size_t n = positions.size(), m = s.nodes.size();
    SkeletonNodeMap map;
    map.meshNodeCount = n;

    // Steps 1–2: r_j from the surface correspondence.
    map.radius.assign(m, 0.0);
    for (size_t i = 0; i < n; ++i) {
        const int32_t j = s.vertexNode[i];
        if (j != kNone) map.radius[j] = std::max(map.radius[j], (positions[i] - s.nodes[j]).norm());
    }

    // Step 3: every node within r_j joins Π_j (its surface correspondences are within r_j by
    // definition of r_j: the same norm is compared, and the correspondence test guards it).
    std::vector<std::vector<int32_t>> pi(m);
    std::vector<char> covered(n, 0);
    for (size_t j = 0; j < m; ++j) {
        const double r = map.radius[j];
        const Vec3& p = s.nodes[j];
        for (size_t i = 0; i < n; ++i) {
            if ((positions[i] - p).norm() <= r || s.vertexNode[i] == static_cast<int32_t>(j)) {
                pi[j].push_back(static_cast<int32_t>(i));
                covered[i] = 1;
            }
        }
    }

    // Coverage guarantee: nodes that no ball reaches go to the nearest node of the skeleton curve.
    const std::vector<int32_t> degree = s.degrees();
    for (size_t i = 0; i < n; ++i) {
        if (covered[i]) continue;
        const int32_t j = projectOnSkeleton(positions[i], s, degree);
        map.fallbackNodes.push_back(static_cast<int32_t>(i));
        map.fallbackNode.push_back(j);
        pi[j].push_back(static_cast<int32_t>(i));
    }
    for (auto& members : pi)
        std::sort(members.begin(), members.end());

    map.start.assign(m + 1, 0);
    for (size_t j = 0; j < m; ++j)
        map.start[j + 1] = map.start[j] + static_cast<int32_t>(pi[j].size());
    map.members.reserve(static_cast<size_t>(map.start[m]));
    for (size_t j = 0; j < m; ++j)
        map.members.insert(map.members.end(), pi[j].begin(), pi[j].end());
    return map;
}

} // namespace viscera::sim
