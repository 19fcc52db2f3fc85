// UV transfer from the source parts to a remeshed surface (bake/uv_transfer.hpp) [A §3.3]: the
// source's islands, charts, seams and search trees; the three transfers; the measures. The seam
// cut is in seam_cut.cpp.
#include "bake/uv_transfer.hpp"
#include "bake/uv_transfer_detail.hpp"

#include "sim/collision/distance.hpp"
#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>

#include <Eigen/SVD>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <map>
#include <numeric>
#include <random>
#include <set>
#include <unordered_map>

namespace viscera::bake {

using detail::edgeKey;
using detail::kInside;
using detail::overTwo;

namespace {

using Vec3 = Eigen::Vector3d;
using Vec2 = Eigen::Vector2d;
using K = CGAL::Simple_cartesian<double>;
using Triangles = std::vector<K::Triangle_3>;
using Primitive = CGAL::AABB_triangle_primitive<K, Triangles::const_iterator>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, Primitive>>;

K::Point_3 cgal(const Vec3& p) {
    return {p.x(), p.y(), p.z()};
}

double percentile(std::vector<double> v, double q) {
    if (v.empty()) return 0;
    const size_t k = std::min(v.size() - 1, size_t(q * double(v.size() - 1) + 0.5));
    std::nth_element(v.begin(), v.begin() + long(k), v.end());
    return v[k];
}

} // namespace

bool detail::overTwo(const UvSource& source, const std::array<Vec3, 3>& p, bool charts, int own) {
    const double tol =
        detail::kStrayTolerance * std::max({(p[1] - p[0]).norm(), (p[2] - p[1]).norm(), (p[0] - p[2]).norm()});
    for (const Vec3& w : kInside) {
        const Vec3 x = w[0] * p[0] + w[1] * p[1] + w[2] * p[2];
        const UvSource::Hit h = source.closest(x);
        if ((charts ? source.chart(h.triangle) : source.island(h.triangle)) == own) continue;
        const double dOwn = (charts ? source.closestOnChart(x, own) : source.closestOnIsland(x, own)).distance;
        if (dOwn - h.distance > tol) return true;
    }
    return false;
}

std::string_view uvTransferMethodName(UvTransferMethod method) {
    switch (method) {
    case UvTransferMethod::ClosestPoint:
        return "closest-point";
    case UvTransferMethod::IslandLabelled:
        return "island-labelled";
    case UvTransferMethod::SeamCutting:
        return "seam-cutting";
    }
    return "seam-cutting";
}

// ---- the source -------------------------------------------------------------------------------

struct UvSource::Impl {
    std::vector<Vec3> points;
    std::vector<std::array<int32_t, 3>> tris;
    std::vector<CornerUv> uv;
    std::vector<int> island;
    std::vector<std::array<int32_t, 3>> across;    ///< neighbour across edge k (corners k, k+1) that is no seam; -1
    std::vector<std::array<int32_t, 3>> acrossAny; ///< neighbour across edge k, seam or not; -1
    int islands = 0;
    /// Charts: the islands, each one whose seams lie inside it (a tube unwrapped into one island)
    /// split in two along them, so that no chart holds a seam: the UVs are continuous on a chart.
    std::vector<int> chart;
    int charts = 0;
    std::vector<SeamSegment> seams;
    struct Search {
        Triangles tris;
        std::vector<size_t> index; ///< source triangle of each tree triangle
        std::unique_ptr<Tree> tree;
    };
    Search all;
    std::vector<Search> perIsland, perChart;
    double cell = 1;
    std::unordered_map<uint64_t, std::vector<int>> grid;

    static void build(Search& s) {
        if (s.tris.empty()) return;
        s.tree = std::make_unique<Tree>(s.tris.cbegin(), s.tris.cend());
        s.tree->accelerate_distance_queries();
    }
    Hit hitAt(size_t t, const Vec3& p) const {
        const auto& c = tris[t];
        Hit h;
        h.triangle = t;
        h.bary = sim::closestPointOnTriangle(p, points[c[0]], points[c[1]], points[c[2]]).bary;
        h.point = h.bary[0] * points[c[0]] + h.bary[1] * points[c[1]] + h.bary[2] * points[c[2]];
        h.uv = h.bary[0] * uv[t][0] + h.bary[1] * uv[t][1] + h.bary[2] * uv[t][2];
        h.distance = (p - h.point).norm();
        return h;
    }
    Hit closestIn(const Search& s, const Vec3& p) const {
        const auto r = s.tree->closest_point_and_primitive(cgal(p));
        return hitAt(s.index[size_t(r.second - s.tris.cbegin())], p);
    }
    std::array<int64_t, 3> cellOf(const Vec3& p) const {
        return {int64_t(std::floor(p.x() / cell)), int64_t(std::floor(p.y() / cell)),
                int64_t(std::floor(p.z() / cell))};
    }
    static uint64_t cellKey(int64_t x, int64_t y, int64_t z) {
        return (uint64_t(x & 0x1fffff) << 42) | (uint64_t(y & 0x1fffff) << 21) | uint64_t(z & 0x1fffff);
    }

    /// A seam edge: its point pair (key) and its two triangles.
    using SeamEdge = std::pair<uint64_t, std::array<int32_t, 2>>;

    void addPart(const RemeshPart& part);
    std::vector<SeamEdge> linkEdges();
    void buildSeams(const std::vector<SeamEdge>& seamEdges);
    void buildCharts(const std::vector<SeamEdge>& seamEdges);
    bool buildTrees();
};

UvSource::UvSource(const std::vector<RemeshPart>& parts) : m_impl(std::make_unique<Impl>()) {
    Impl& m = *m_impl;
    for (const RemeshPart& part : parts)
        m.addPart(part);
    const auto seamEdges = m.linkEdges();
    m.buildSeams(seamEdges);
    m.buildCharts(seamEdges);
    if (!m.buildTrees()) throw InputError(parts.front().name + ": every triangle of the parts is degenerate");
}

void UvSource::Impl::addPart(const RemeshPart& part) {
    if (part.uv.empty()) throw InputError(part.name + ": the part has no UVs (the transfer needs UVs on every part)");
    if (part.uv.size() != part.surface.triangleCount())
        throw InputError(part.name + ": " + std::to_string(part.uv.size()) + " UV triangles for " +
                         std::to_string(part.surface.triangleCount()) + " triangles (one per triangle expected)");
    // Weld: vertices at the same position are one point (render meshes split them at seams).
    std::map<std::array<double, 3>, int32_t> weld;
    std::vector<int32_t> local(part.surface.vertexCount());
    for (size_t v = 0; v < local.size(); ++v) {
        const Vec3& p = part.surface.positions()[v];
        const auto [it, fresh] = weld.try_emplace({p.x(), p.y(), p.z()}, int32_t(points.size()));
        if (fresh) points.push_back(p);
        local[v] = it->second;
    }
    for (size_t t = 0; t < part.surface.triangleCount(); ++t) {
        const sim::Tri& tri = part.surface.triangles()[t];
        for (int k = 0; k < 3; ++k)
            if (!part.uv[t][k].allFinite())
                throw InputError(part.name + ": triangle " + std::to_string(t) + " corner " + std::to_string(k) +
                                 ": UV is not finite");
        tris.push_back({local[tri[0]], local[tri[1]], local[tri[2]]});
        uv.push_back(part.uv[t]);
    }
}

/// Neighbours across every edge, islands (union-find across edges whose two sides have the same
/// UVs at both ends) and the seam edges (the other shared edges), in key order.
std::vector<UvSource::Impl::SeamEdge> UvSource::Impl::linkEdges() {
    const size_t n = tris.size();
    across.assign(n, {-1, -1, -1});
    acrossAny.assign(n, {-1, -1, -1});
    std::unordered_map<uint64_t, std::vector<std::pair<int32_t, int>>> edges;
    edges.reserve(3 * n);
    for (size_t t = 0; t < n; ++t)
        for (int k = 0; k < 3; ++k)
            edges[edgeKey(tris[t][k], tris[t][(k + 1) % 3])].push_back({int32_t(t), k});
    std::vector<int32_t> parent(n);
    std::iota(parent.begin(), parent.end(), 0);
    auto find = [&](int32_t x) {
        while (parent[x] != x)
            x = parent[x] = parent[parent[x]];
        return x;
    };
    auto uvAt = [&](int32_t t, int32_t point) -> const Vec2& {
        const auto& c = tris[t];
        return uv[t][c[0] == point ? 0 : c[1] == point ? 1 : 2];
    };
    std::vector<SeamEdge> seamEdges;
    for (const auto& [key, list] : edges) {
        if (list.size() != 2) continue; // a border, or a non-manifold edge: no neighbour
        const auto [t0, k0] = list[0];
        const auto [t1, k1] = list[1];
        const int32_t a = int32_t(key >> 32), b = int32_t(key & 0xffffffffu);
        acrossAny[t0][k0] = t1;
        acrossAny[t1][k1] = t0;
        const double tol = 1e-7;
        if ((uvAt(t0, a) - uvAt(t1, a)).norm() <= tol && (uvAt(t0, b) - uvAt(t1, b)).norm() <= tol) {
            across[t0][k0] = t1;
            across[t1][k1] = t0;
            parent[find(t0)] = find(t1);
        } else {
            seamEdges.push_back({key, {t0, t1}});
        }
    }
    std::vector<int> label(n, -1);
    island.resize(n);
    for (size_t t = 0; t < n; ++t) {
        const int32_t r = find(int32_t(t));
        if (label[r] < 0) label[r] = islands++;
        island[t] = label[r];
    }
    std::sort(seamEdges.begin(), seamEdges.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
    return seamEdges;
}

/// Seam segments with the mean normal of their two triangles, and the grid that finds them.
void UvSource::Impl::buildSeams(const std::vector<SeamEdge>& seamEdges) {
    auto normalOf = [&](int32_t t) {
        const auto& c = tris[t];
        const Vec3 nrm = (points[c[1]] - points[c[0]]).cross(points[c[2]] - points[c[0]]);
        return nrm.norm() > 0 ? Vec3(nrm.normalized()) : Vec3::Zero();
    };
    double lengthSum = 0;
    for (const auto& [key, faces] : seamEdges) {
        SeamSegment s;
        s.a = points[int32_t(key >> 32)];
        s.b = points[int32_t(key & 0xffffffffu)];
        Vec3 nrm = normalOf(faces[0]) + normalOf(faces[1]);
        if (nrm.norm() < 1e-12) nrm = normalOf(faces[0]);
        s.normal = nrm.norm() > 0 ? Vec3(nrm.normalized()) : Vec3::UnitZ();
        lengthSum += (s.b - s.a).norm();
        seams.push_back(s);
    }
    cell = seams.empty() ? 1.0 : std::max(2.0 * lengthSum / double(seams.size()), 1e-6);
    for (size_t i = 0; i < seams.size(); ++i) {
        const auto c0 = cellOf(seams[i].a.cwiseMin(seams[i].b)), c1 = cellOf(seams[i].a.cwiseMax(seams[i].b));
        for (int64_t x = c0[0]; x <= c1[0]; ++x)
            for (int64_t y = c0[1]; y <= c1[1]; ++y)
                for (int64_t z = c0[2]; z <= c1[2]; ++z)
                    grid[cellKey(x, y, z)].push_back(int(i));
    }
}

/// Charts: an island with seams inside it is split in two. Its inner seam edges are chained
/// (a walk orients them), the triangle on the left of each is seeded with side 0 and the one on
/// the right with side 1, and both sides grow across the island's non-seam edges, breadth first:
/// they meet away from the seam, where the UVs are continuous (that border is no seam).
void UvSource::Impl::buildCharts(const std::vector<SeamEdge>& seamEdges) {
    const size_t n = tris.size();
    std::unordered_map<int32_t, std::vector<size_t>> byPoint; // inner seam edges at each point
    std::vector<size_t> inner;
    for (size_t i = 0; i < seamEdges.size(); ++i) {
        const auto& [key, faces] = seamEdges[i];
        if (island[size_t(faces[0])] != island[size_t(faces[1])]) continue;
        inner.push_back(i);
        byPoint[int32_t(key >> 32)].push_back(i);
        byPoint[int32_t(key & 0xffffffffu)].push_back(i);
    }
    std::vector<int> side(n, -1);
    std::vector<size_t> queue;
    std::unordered_map<size_t, char> walked;
    auto seed = [&](int32_t t, int s) {
        if (side[size_t(t)] < 0) {
            side[size_t(t)] = s;
            queue.push_back(size_t(t));
        }
    };
    for (size_t first : inner) {
        if (walked.count(first)) continue;
        // Walk the chain from this edge, each edge oriented from the point it was reached by.
        std::vector<std::pair<size_t, int32_t>> stack{{first, int32_t(seamEdges[first].first >> 32)}};
        walked[first] = 1;
        while (!stack.empty()) {
            const auto [e, from] = stack.back();
            stack.pop_back();
            const auto& [key, faces] = seamEdges[e];
            const int32_t a = int32_t(key >> 32), b = int32_t(key & 0xffffffffu), to = from == a ? b : a;
            for (int f = 0; f < 2; ++f) {
                const auto& c = tris[size_t(faces[size_t(f)])];
                const bool left =
                    (c[0] == from && c[1] == to) || (c[1] == from && c[2] == to) || (c[2] == from && c[0] == to);
                seed(faces[size_t(f)], left ? 0 : 1);
            }
            for (size_t next : byPoint[to])
                if (walked.emplace(next, 1).second) stack.push_back({next, to});
            for (size_t next : byPoint[from])
                if (walked.emplace(next, 1).second) stack.push_back({next, from});
        }
    }
    for (size_t i = 0; i < queue.size(); ++i)
        for (int32_t nb : across[queue[i]])
            if (nb >= 0 && side[size_t(nb)] < 0) {
                side[size_t(nb)] = side[queue[i]];
                queue.push_back(size_t(nb));
            }
    std::map<std::pair<int, int>, int> id;
    chart.resize(n);
    for (size_t t = 0; t < n; ++t) {
        const auto [it, fresh] = id.try_emplace({island[t], std::max(side[t], 0)}, charts);
        if (fresh) ++charts;
        chart[t] = it->second;
    }
}

/// Search trees: all triangles, one per island, one per chart. False when every triangle is degenerate.
bool UvSource::Impl::buildTrees() {
    perIsland.resize(size_t(islands));
    perChart.resize(size_t(charts));
    for (size_t t = 0; t < tris.size(); ++t) {
        const auto& c = tris[t];
        const K::Triangle_3 tri(cgal(points[c[0]]), cgal(points[c[1]]), cgal(points[c[2]]));
        if (tri.is_degenerate()) continue;
        for (Search* s : {&all, &perIsland[size_t(island[t])], &perChart[size_t(chart[t])]}) {
            s->tris.push_back(tri);
            s->index.push_back(t);
        }
    }
    if (all.tris.empty()) return false;
    build(all);
    for (auto* list : {&perIsland, &perChart})
        for (auto& s : *list)
            build(s);
    return true;
}

UvSource::~UvSource() = default;

size_t UvSource::triangleCount() const {
    return m_impl->tris.size();
}
size_t UvSource::islandCount() const {
    return size_t(m_impl->islands);
}
size_t UvSource::seamEdgeCount() const {
    return m_impl->seams.size();
}
int UvSource::island(size_t t) const {
    return m_impl->island[t];
}
const std::vector<UvSource::SeamSegment>& UvSource::seamSegments() const {
    return m_impl->seams;
}
const CornerUv& UvSource::cornerUv(size_t t) const {
    return m_impl->uv[t];
}

std::array<Vec3, 3> UvSource::corners(size_t t) const {
    const auto& c = m_impl->tris[t];
    return {m_impl->points[c[0]], m_impl->points[c[1]], m_impl->points[c[2]]};
}

int32_t UvSource::neighbourAcross(size_t t, int k) const {
    return m_impl->acrossAny[t][k];
}

UvSource::Hit UvSource::closest(const Vec3& p) const {
    // A point off a ridge (a seam on a faceted surface) is closest to the ridge edge from a whole
    // wedge, where the tree picks either side: the triangle the point lies over (its normal
    // closest to the direction from the edge to the point) takes it, so the sides split the
    // wedge along its bisector and labels do not flicker from one query to the next.
    Hit best = m_impl->closestIn(m_impl->all, p);
    const Vec3 away = p - best.point;
    if (!(away.norm() > 0)) return best;
    auto facing = [&](size_t t) {
        const auto q = corners(t);
        const Vec3 n = (q[1] - q[0]).cross(q[2] - q[0]);
        return n.norm() > 0 ? n.normalized().dot(away) : -away.norm();
    };
    const size_t first = best.triangle;
    double bestFacing = facing(first);
    for (int k = 0; k < 3; ++k) {
        if (best.triangle != first || m_impl->hitAt(first, p).bary[(k + 2) % 3] > 1e-9) continue; // not on edge k
        const int32_t nb = m_impl->acrossAny[first][k];
        if (nb < 0) continue;
        const Hit h = m_impl->hitAt(size_t(nb), p);
        if (h.distance > best.distance * (1 + 1e-9) + 1e-15) continue;
        const double f = facing(size_t(nb));
        if (f > bestFacing) {
            best = h;
            bestFacing = f;
        }
    }
    return best;
}

size_t UvSource::chartCount() const {
    return size_t(m_impl->charts);
}
int UvSource::chart(size_t t) const {
    return m_impl->chart[t];
}

UvSource::Hit UvSource::closestOnChart(const Vec3& p, int chart) const {
    if (chart < 0 || chart >= m_impl->charts || !m_impl->perChart[size_t(chart)].tree) return closest(p);
    return m_impl->closestIn(m_impl->perChart[size_t(chart)], p);
}

UvSource::Hit UvSource::closestOnIsland(const Vec3& p, int island) const {
    if (island < 0 || island >= m_impl->islands || !m_impl->perIsland[size_t(island)].tree) return closest(p);
    return m_impl->closestIn(m_impl->perIsland[size_t(island)], p);
}

UvSource::Hit UvSource::closestAmong(const Vec3& p, const std::vector<size_t>& triangles) const {
    Hit best;
    best.distance = std::numeric_limits<double>::infinity();
    for (size_t t : triangles) {
        const Hit h = m_impl->hitAt(t, p);
        if (h.distance < best.distance) best = h;
    }
    return best;
}

void UvSource::seamSegmentsNear(const Vec3& lo, const Vec3& hi, double margin, std::vector<int>& out) const {
    out.clear();
    const Impl& m = *m_impl;
    if (m.seams.empty()) return;
    const Vec3 l = lo.array() - margin, h = hi.array() + margin;
    const auto c0 = m.cellOf(l), c1 = m.cellOf(h);
    const double cells = double(c1[0] - c0[0] + 1) * double(c1[1] - c0[1] + 1) * double(c1[2] - c0[2] + 1);
    if (cells > 4096) { // a box larger than the seams' cells: every segment
        out.resize(m.seams.size());
        std::iota(out.begin(), out.end(), 0);
        return;
    }
    for (int64_t x = c0[0]; x <= c1[0]; ++x)
        for (int64_t y = c0[1]; y <= c1[1]; ++y)
            for (int64_t z = c0[2]; z <= c1[2]; ++z) {
                const auto it = m.grid.find(Impl::cellKey(x, y, z));
                if (it != m.grid.end()) out.insert(out.end(), it->second.begin(), it->second.end());
            }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
}

double UvSource::distanceToSeam(const Vec3& p, double margin) const {
    std::vector<int> near;
    seamSegmentsNear(p, p, margin, near);
    double best = std::numeric_limits<double>::infinity();
    for (int i : near) {
        const SeamSegment& s = m_impl->seams[size_t(i)];
        const Vec3 d = s.b - s.a;
        const double t = d.squaredNorm() > 0 ? std::clamp((p - s.a).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.0;
        best = std::min(best, (p - (s.a + t * d)).norm());
    }
    return best;
}

// ---- the transfers ----------------------------------------------------------------------------

namespace {

std::array<Vec3, 3> cornersOf(const sim::TriMesh& m, size_t t) {
    const sim::Tri& c = m.triangles()[t];
    return {m.positions()[c[0]], m.positions()[c[1]], m.positions()[c[2]]};
}

} // namespace

std::vector<CornerUv> transferUv(const UvSource& source, const sim::TriMesh& target, UvTransferMethod method) {
    std::vector<CornerUv> uv(target.triangleCount());
    if (method == UvTransferMethod::ClosestPoint) {
        std::vector<Vec2> perVertex(target.vertexCount());
        for (size_t v = 0; v < perVertex.size(); ++v)
            perVertex[v] = source.closest(target.positions()[v]).uv;
        for (size_t t = 0; t < uv.size(); ++t)
            for (int k = 0; k < 3; ++k)
                uv[t][k] = perVertex[target.triangles()[t][k]];
        return uv;
    }
    for (size_t t = 0; t < uv.size(); ++t) {
        const auto p = cornersOf(target, t);
        const Vec3 centre = (p[0] + p[1] + p[2]) / 3.0;
        if (method == UvTransferMethod::IslandLabelled) {
            // The island that covers most of the triangle (its inside samples, the centroid first).
            std::array<int, 4> isl{};
            for (size_t s = 0; s < kInside.size(); ++s)
                isl[s] = source.island(
                    source.closest(kInside[s][0] * p[0] + kInside[s][1] * p[1] + kInside[s][2] * p[2]).triangle);
            int best = isl[0], bestCount = 0;
            for (int cand : isl) {
                const int count = int(std::count(isl.begin(), isl.end(), cand));
                if (count > bestCount) {
                    best = cand;
                    bestCount = count;
                }
            }
            for (int k = 0; k < 3; ++k)
                uv[t][k] = source.closestOnIsland(p[k], best).uv;
        } else {
            // Seam cutting: one host chart per triangle (the chart of its centroid's closest point:
            // no seam inside it), each corner at its closest point on that chart.
            const int chart = source.chart(source.closest(centre).triangle);
            for (int k = 0; k < 3; ++k)
                uv[t][k] = source.closestOnChart(p[k], chart).uv;
        }
    }
    return uv;
}

// ---- the measures -----------------------------------------------------------------------------

namespace {

/// The crossings of segment (pa, pb) of the intermediate mesh (on the source) with the source's
/// seams, as sorted fractions from pa; crossings within 3 % of an end flagged as lying on the seam
/// are that end, not a crossing.
struct Crossing {
    double t = 0; ///< fraction along the edge
    int seam = 0; ///< the seam segment
};

std::vector<Crossing> seamCrossings(const UvSource& source, const Vec3& pa, const Vec3& pb, bool aOnSeam, bool bOnSeam,
                                    std::vector<int>& near) {
    constexpr double kEndTol = 0.03;
    std::vector<Crossing> ts;
    const double len = (pb - pa).norm();
    if (!(len > 0)) return ts;
    const auto& seams = source.seamSegments();
    source.seamSegmentsNear(pa.cwiseMin(pb), pa.cwiseMax(pb), 0.3 * len, near);
    for (int i : near) {
        const UvSource::SeamSegment& s = seams[size_t(i)];
        const Vec3 d = s.b - s.a;
        const double sa = d.cross(pa - s.a).dot(s.normal), sb = d.cross(pb - s.a).dot(s.normal);
        if (!(sa * sb < 0)) continue; // both ends on one side of the seam's line
        // An end on the line (to rounding: a cut vertex) touches the seam there, it does not cross.
        const double onLine = 1e-7 * len * d.norm();
        if (std::abs(sa) <= onLine || std::abs(sb) <= onLine) continue;
        const sim::SegmentPair sp = sim::closestPointsSegments(pa, pb, s.a, s.b);
        const double t = sp.s, r = sp.t;
        // The crossing must lie on the seam segment (a little beyond its ends: the polyline's
        // joints) and near the edge (a chord over a curved surface passes just under it).
        const Vec3 x = pa + t * (pb - pa), y = s.a + r * d;
        if ((x - y).norm() > 0.3 * len) continue;
        const double along = d.squaredNorm() > 0 ? (x - s.a).dot(d) / d.squaredNorm() : 0.0;
        if (along < -0.02 || along > 1.02) continue;
        if (aOnSeam && t < kEndTol) continue;
        if (bOnSeam && t > 1 - kEndTol) continue;
        ts.push_back({t, i});
    }
    std::sort(ts.begin(), ts.end(), [](const Crossing& x, const Crossing& y) { return x.t < y.t; });
    std::vector<Crossing> merged;
    for (const Crossing& c : ts)
        if (merged.empty() || c.t - merged.back().t > 0.02) merged.push_back(c);
    return merged;
}

/// The distortion of one target triangle's UVs: target triangle → (its UVs) → the host's UV map
/// inverted → host plane, in the target's frame. A perfect transfer makes this nearly the
/// projection: σ1 = σ2 = 1 (angle σ1/σ2, area factor max(σ1σ2, 1/σ1σ2)).
struct Distortion {
    enum Kind { Measured, Flipped, Unmeasured } kind = Unmeasured;
    double angle = 1, area = 1;
};

Distortion distortion(const UvSource& source, const std::array<Vec3, 3>& p, const CornerUv& uv) {
    const Vec3 e1v = p[1] - p[0], e2v = p[2] - p[0], n = e1v.cross(e2v);
    if (!(n.norm() > 0) || !(e1v.norm() > 0)) return {}; // a degenerate target triangle
    const Vec3 f1 = e1v.normalized(), f2 = n.normalized().cross(f1);
    Eigen::Matrix2d P, U, Q, V;
    P << e1v.dot(f1), e2v.dot(f1), e1v.dot(f2), e2v.dot(f2);
    U.col(0) = uv[1] - uv[0];
    U.col(1) = uv[2] - uv[0];
    const UvSource::Hit host = source.closest((p[0] + p[1] + p[2]) / 3.0);
    const auto q = source.corners(host.triangle);
    const CornerUv& hv = source.cornerUv(host.triangle);
    Q << (q[1] - q[0]).dot(f1), (q[2] - q[0]).dot(f1), (q[1] - q[0]).dot(f2), (q[2] - q[0]).dot(f2);
    V.col(0) = hv[1] - hv[0];
    V.col(1) = hv[2] - hv[0];
    const double hostArea = 0.5 * (q[1] - q[0]).cross(q[2] - q[0]).norm();
    if (!(std::abs(V.determinant()) > 1e-14) || !(std::abs(Q.determinant()) > 0.2 * hostArea))
        return {}; // the source itself has no usable map here (degenerate UVs, or a host across the plane)
    const Eigen::Matrix2d C = (Q * V.inverse()) * (U * P.inverse());
    const double det = C.determinant();
    if (!(det > 0) || !C.allFinite()) return {Distortion::Flipped};
    const Eigen::Vector2d s = Eigen::JacobiSVD<Eigen::Matrix2d>(C).singularValues();
    // A UV image squeezed to (nearly) a line is degenerate: counted with the flipped ones, so the
    // figures stay finite.
    if (!(s[1] > 1e-9 * s[0]) || !(det > 1e-12)) return {Distortion::Flipped};
    return {Distortion::Measured, s[0] / s[1], std::max(det, 1.0 / det)};
}

} // namespace

UvTransferStats measureUvTransfer(const UvSource& source, const sim::TriMesh& target, const std::vector<CornerUv>& uv,
                                  size_t samples) {
    if (uv.size() != target.triangleCount())
        throw std::invalid_argument("bake::measureUvTransfer(): one UV triangle per target triangle expected");
    UvTransferStats st;
    st.triangles = target.triangleCount();
    st.faceStretch.assign(st.triangles, 0.0);
    std::vector<double> angles, areas;
    size_t over = 0;
    // Triangles a seam passes through: an edge of the intermediate mesh crossed away from its ends
    // (a crossing within 3 % of a vertex is the vertex lying on the seam).
    std::vector<Vec3> proj(target.vertexCount());
    for (size_t v = 0; v < proj.size(); ++v)
        proj[v] = source.closest(target.positions()[v]).point;
    std::unordered_map<uint64_t, bool> crossed;
    std::vector<int> near;
    for (size_t t = 0; t < st.triangles; ++t) {
        const sim::Tri& f = target.triangles()[t];
        bool any = false;
        for (int k = 0; k < 3; ++k) {
            const int32_t a = std::min(f[k], f[(k + 1) % 3]), b = std::max(f[k], f[(k + 1) % 3]);
            auto [it, fresh] = crossed.try_emplace(edgeKey(a, b), false);
            if (fresh) it->second = !seamCrossings(source, proj[a], proj[b], true, true, near).empty();
            any = any || it->second;
        }
        st.seamCrossed += any ? 1 : 0;
    }
    for (size_t t = 0; t < st.triangles; ++t) {
        const auto p = cornersOf(target, t);
        // Spanning: an inside sample lies on another island than the centroid's (overTwo).
        const int own = source.island(source.closest((p[0] + p[1] + p[2]) / 3.0).triangle);
        st.spanningIslands += overTwo(source, p, false, own) ? 1 : 0;
        const Distortion d = distortion(source, p, uv[t]);
        if (d.kind == Distortion::Unmeasured) continue;
        if (d.kind == Distortion::Flipped) {
            ++st.flipped;
            ++over;
            st.faceStretch[t] = std::numeric_limits<double>::infinity();
            continue;
        }
        const double angle = d.angle, area = d.area;
        angles.push_back(angle);
        areas.push_back(area);
        st.faceStretch[t] = std::max(angle, area);
        if (angle > kUvStretchThreshold || area > kUvStretchThreshold) ++over;
    }
    st.angleP50 = percentile(angles, 0.5);
    st.angleP95 = percentile(angles, 0.95);
    st.angleMax = angles.empty() ? 0 : *std::max_element(angles.begin(), angles.end());
    st.areaP50 = percentile(areas, 0.5);
    st.areaP95 = percentile(areas, 0.95);
    st.areaMax = areas.empty() ? 0 : *std::max_element(areas.begin(), areas.end());
    st.overThreshold = st.triangles ? double(over) / double(st.triangles) : 0;
    // UV error at area-weighted surface samples (fixed seed: repeatable).
    std::vector<double> cumulative(st.triangles);
    double total = 0;
    for (size_t t = 0; t < st.triangles; ++t) {
        const auto p = cornersOf(target, t);
        total += 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).norm();
        cumulative[t] = total;
    }
    std::mt19937_64 rng(20261203);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::vector<double> errors;
    errors.reserve(samples);
    for (size_t i = 0; i < samples && total > 0; ++i) {
        const size_t t =
            size_t(std::lower_bound(cumulative.begin(), cumulative.end(), unit(rng) * total) - cumulative.begin());
        if (t >= st.triangles) continue;
        double r1 = unit(rng), r2 = unit(rng);
        if (r1 + r2 > 1) {
            r1 = 1 - r1;
            r2 = 1 - r2;
        }
        const Vec3 w(1 - r1 - r2, r1, r2);
        const auto p = cornersOf(target, t);
        const Vec3 x = w[0] * p[0] + w[1] * p[1] + w[2] * p[2];
        const Vec2 got = w[0] * uv[t][0] + w[1] * uv[t][1] + w[2] * uv[t][2];
        // The reference: the closest source point's UV; on a seam edge either side's UV counts.
        const UvSource::Hit h = source.closest(x);
        double err = (got - h.uv).norm();
        for (int k = 0; k < 3; ++k) {
            if (h.bary[(k + 2) % 3] > 1e-9) continue; // not on edge k (corners k, k+1)
            const int32_t nb = source.neighbourAcross(h.triangle, k);
            if (nb >= 0) err = std::min(err, (got - source.closestAmong(x, {size_t(nb)}).uv).norm());
        }
        errors.push_back(err);
    }
    st.samples = errors.size();
    if (!errors.empty()) {
        st.uvErrorMean = std::accumulate(errors.begin(), errors.end(), 0.0) / double(errors.size());
        st.uvErrorP95 = percentile(errors, 0.95);
        st.uvErrorMax = *std::max_element(errors.begin(), errors.end());
    }
    return st;
}

void writeObjWithUv(const std::string& path, const sim::TriMesh& mesh, const std::vector<CornerUv>& uv) {
    if (uv.size() != mesh.triangleCount())
        throw std::invalid_argument("bake::writeObjWithUv(): one UV triangle per triangle expected");
    std::string text = "# viscera-studio remesh: " + std::to_string(mesh.vertexCount()) + " vertices, " +
                       std::to_string(mesh.triangleCount()) + " triangles, metres, per-corner UVs\n";
    char line[160];
    for (const Vec3& p : mesh.positions()) {
        std::snprintf(line, sizeof line, "v %.9g %.9g %.9g\n", p.x(), p.y(), p.z());
        text += line;
    }
    std::map<std::pair<double, double>, int> index;
    std::vector<std::array<int, 3>> corner(uv.size());
    for (size_t t = 0; t < uv.size(); ++t)
        for (int k = 0; k < 3; ++k) {
            const auto [it, fresh] = index.try_emplace({uv[t][k].x(), uv[t][k].y()}, int(index.size()) + 1);
            if (fresh) {
                std::snprintf(line, sizeof line, "vt %.9g %.9g\n", uv[t][k].x(), uv[t][k].y());
                text += line;
            }
            corner[t][k] = it->second;
        }
    for (size_t t = 0; t < uv.size(); ++t) {
        const sim::Tri& f = mesh.triangles()[t];
        std::snprintf(line, sizeof line, "f %d/%d %d/%d %d/%d\n", f[0] + 1, corner[t][0], f[1] + 1, corner[t][1],
                      f[2] + 1, corner[t][2]);
        text += line;
    }
    writeFileAtomic(path, text);
}

} // namespace viscera::bake
