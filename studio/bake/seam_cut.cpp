// The seam cut of a remeshed target along the source's UV seams and chart borders
// (bake/uv_transfer.hpp, cutAlongSeams) [A §3.3.4, Algorithm 1, lines 3–8 and 13–15].
#include "bake/uv_transfer.hpp"
#include "bake/uv_transfer_detail.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <stdexcept>
#include <unordered_map>

namespace viscera::bake {

using detail::edgeKey;
using detail::kInside;
using detail::overTwo;
using Vec3 = Eigen::Vector3d;

namespace {

/// Replaces every triangle with split edges (a new vertex per edge in `edgePoint`) by its pieces,
/// keeping the winding: one split edge gives two triangles, two give three (the quad split along
/// its shorter diagonal), three give four. Shared edges split at one shared vertex, so the mesh
/// stays conforming. Returns the number of triangles replaced.
size_t subdivide(const std::vector<Vec3>& pos, std::vector<sim::Tri>& tris,
                 const std::unordered_map<uint64_t, int32_t>& edgePoint) {
    std::vector<sim::Tri> out;
    out.reserve(tris.size() + 3 * edgePoint.size());
    size_t replaced = 0;
    auto mid = [&](int32_t a, int32_t b) {
        const auto it = edgePoint.find(edgeKey(a, b));
        return it == edgePoint.end() ? -1 : it->second;
    };
    for (const sim::Tri& t0 : tris) {
        std::array<int32_t, 3> m{mid(t0[0], t0[1]), mid(t0[1], t0[2]), mid(t0[2], t0[0])};
        const int count = (m[0] >= 0) + (m[1] >= 0) + (m[2] >= 0);
        if (count == 0) {
            out.push_back(t0);
            continue;
        }
        ++replaced;
        if (count == 3) {
            out.push_back({t0[0], m[0], m[2]});
            out.push_back({m[0], t0[1], m[1]});
            out.push_back({m[2], m[1], t0[2]});
            out.push_back({m[0], m[1], m[2]});
            continue;
        }
        // Rotate so that edge 0 (v0, v1) is split and, with two, edge 1 (v1, v2) as well.
        int r = 0;
        if (count == 1)
            r = m[0] >= 0 ? 0 : m[1] >= 0 ? 1 : 2;
        else
            r = m[2] < 0 ? 0 : m[0] < 0 ? 1 : 2;
        const int32_t v0 = t0[r], v1 = t0[(r + 1) % 3], v2 = t0[(r + 2) % 3];
        const int32_t m01 = m[r], m12 = m[(r + 1) % 3];
        if (count == 1) {
            out.push_back({v0, m01, v2});
            out.push_back({m01, v1, v2});
        } else {
            out.push_back({m01, v1, m12});
            if ((pos[v0] - pos[m12]).squaredNorm() <= (pos[m01] - pos[v2]).squaredNorm()) {
                out.push_back({v0, m01, m12});
                out.push_back({v0, m12, v2});
            } else {
                out.push_back({v0, m01, v2});
                out.push_back({m01, m12, v2});
            }
        }
    }
    tris = std::move(out);
    return replaced;
}

/// The fraction along target edge (xa, xb), chart `a` at xa and chart `b` at xb (the charts of
/// their closest source points), where the surface passes from one to the other: the root of
/// d_a(x) − d_b(x), the distances to the two charts, by bisection. Unlike the label it is
/// continuous along the edge, ≤ 0 at xa and ≥ 0 at xb, also where two parts meet and the target
/// (smoothed by the remesh) lies off both. Off a ridge the two are equal over a wedge: there the
/// side the point faces decides (UvSource::closest), as it does for the labels.
double chartBorder(const UvSource& source, int a, int b, const Vec3& xa, const Vec3& xb) {
    auto towardA = [&](double u) {
        const Vec3 x = xa + u * (xb - xa);
        const double da = source.closestOnChart(x, a).distance, db = source.closestOnChart(x, b).distance;
        const double tol = 1e-9 * (da + db) + 1e-12;
        if (std::abs(da - db) > tol) return da < db;
        return source.chart(source.closest(x).triangle) == a; // off a ridge, equally far: its facing side
    };
    double lo = 0, hi = 1;
    for (int i = 0; i < 30; ++i) {
        const double mid = 0.5 * (lo + hi);
        (towardA(mid) ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

/// The cut of Algorithm 1 as marching triangles over the chart of each vertex's closest source
/// point: refine where a thin strip of a third chart crosses an edge, split every edge between
/// two charts at their border, split the triangles into pieces of one chart each, then snap:
/// a vertex next to a cut point moves onto it (the edge between them collapses) instead of
/// leaving a sliver.
class SeamCutter {
public:
    SeamCutter(const UvSource& source, const sim::TriMesh& target)
        : m_src(source), m_pos(target.positions()), m_tris(target.triangles()) {
        for (const Vec3& x : m_pos)
            m_chart.push_back(chartAt(x));
    }

    /// Halves, up to `rounds` times, the edges whose midpoint lies on a chart neither end is on.
    /// Returns the edges halved; `left` gets those still so after the last round.
    size_t refine(int rounds, size_t& left) {
        size_t halved = 0;
        for (int r = 0;; ++r) {
            std::unordered_map<uint64_t, int32_t> halve;
            for (const auto& [a, b] : edges()) {
                const int mid = chartAt(0.5 * (m_pos[a] + m_pos[b]));
                if (mid != m_chart[a] && mid != m_chart[b]) halve.emplace(edgeKey(a, b), -1);
            }
            if (halve.empty() || r == rounds) {
                left = halve.size();
                return halved;
            }
            std::vector<uint64_t> keys;
            for (const auto& [key, v] : halve)
                keys.push_back(key);
            std::sort(keys.begin(), keys.end());
            for (uint64_t key : keys)
                halve[key] = addVertex(0.5 * (m_pos[size_t(key >> 32)] + m_pos[size_t(key & 0xffffffffu)]),
                                       chartAt(0.5 * (m_pos[size_t(key >> 32)] + m_pos[size_t(key & 0xffffffffu)])));
            halved += halve.size();
            subdivide(m_pos, m_tris, halve);
        }
    }

    /// Splits every edge between two charts at their border and every triangle into pieces of one
    /// chart. Returns the triangles replaced; `crossed` gets the edges split.
    size_t cut(size_t& crossed) {
        std::unordered_map<uint64_t, int32_t> at;
        for (const auto& [a, b] : edges()) {
            if (m_chart[a] < 0 || m_chart[b] < 0 || m_chart[a] == m_chart[b]) continue;
            // A split within 1 % of an end (a snap refused) leaves a sliver, not a degenerate triangle.
            const double t = std::clamp(border(a, b), 0.01, 0.99);
            at[edgeKey(a, b)] = addVertex(m_pos[a] + t * (m_pos[b] - m_pos[a]), -1);
        }
        crossed = at.size();
        m_pieceChart.clear();
        std::vector<sim::Tri> out;
        size_t replaced = 0;
        for (const sim::Tri& t : m_tris) {
            const std::array<int, 3> c{m_chart[t[0]], m_chart[t[1]], m_chart[t[2]]};
            std::set<int> charts(c.begin(), c.end());
            charts.erase(-1);
            if (charts.size() <= 1) {
                piece(out, t,
                      charts.empty() ? chartAt((m_pos[t[0]] + m_pos[t[1]] + m_pos[t[2]]) / 3.0) : *charts.begin());
                continue;
            }
            ++replaced;
            auto mid = [&](int k) { return at.at(edgeKey(t[k], t[(k + 1) % 3])); };
            if (charts.size() == 3) {
                splitThree(out, t, c, {mid(0), mid(1), mid(2)});
            } else if (c[0] < 0 || c[1] < 0 || c[2] < 0) { // a corner on the border, the other two apart
                const int n = c[0] < 0 ? 0 : c[1] < 0 ? 1 : 2;
                const int32_t v1 = t[(n + 1) % 3], v2 = t[(n + 2) % 3], m = mid((n + 1) % 3);
                piece(out, {t[n], v1, m}, m_chart[v1]);
                piece(out, {t[n], m, v2}, m_chart[v2]);
            } else {
                splitTwo(out, t, c, mid);
            }
        }
        m_tris = std::move(out);
        return replaced;
    }

    /// After a cut: the pieces an inside sample point of which lies on another chart (the border
    /// bends inside them) have their edges halved, the midpoints taking their own charts, for the
    /// next cut (with `split`). Returns the pieces found.
    size_t splitStrayPieces(bool split) {
        std::unordered_map<uint64_t, int32_t> halve;
        size_t stray = 0;
        for (size_t f = 0; f < m_tris.size(); ++f) {
            const sim::Tri& t = m_tris[f];
            if (!overTwo(m_src, {m_pos[t[0]], m_pos[t[1]], m_pos[t[2]]}, true, m_pieceChart[f])) continue;
            ++stray;
            for (int k = 0; k < 3 && split; ++k)
                halve.emplace(edgeKey(t[k], t[(k + 1) % 3]), -1);
        }
        if (halve.empty()) return stray; // nothing split: the pieces and their charts stand (finish reads them)
        std::vector<uint64_t> keys;
        for (const auto& [key, v] : halve)
            keys.push_back(key);
        std::sort(keys.begin(), keys.end());
        for (uint64_t key : keys) {
            const Vec3 x = 0.5 * (m_pos[size_t(key >> 32)] + m_pos[size_t(key & 0xffffffffu)]);
            halve[key] = addVertex(x, chartAt(x));
        }
        subdivide(m_pos, m_tris, halve);
        m_pieceChart.clear(); // the next cut labels the new pieces
        return stray;
    }

    /// Before the cut: moves a vertex within `fraction` of the border on one of its edges onto
    /// that border point (the nearest first) instead of leaving a sliver, where its neighbours lie
    /// on two charts only and no triangle around it folds. The vertex is then on the border (chart
    /// −1): the edges from it are not cut. Returns the vertices moved.
    size_t snap(double fraction) {
        struct Candidate {
            double dist;
            int32_t v;
            Vec3 to;
        };
        std::vector<Candidate> list;
        for (const auto& [a, b] : edges()) {
            if (m_chart[a] < 0 || m_chart[b] < 0 || m_chart[a] == m_chart[b]) continue;
            const double t = border(a, b), len = (m_pos[b] - m_pos[a]).norm();
            const Vec3 x = m_pos[a] + t * (m_pos[b] - m_pos[a]);
            if (t < fraction) list.push_back({t * len, a, x});
            if (t > 1 - fraction) list.push_back({(1 - t) * len, b, x});
        }
        std::sort(list.begin(), list.end(), [](const Candidate& x, const Candidate& y) {
            return x.dist != y.dist ? x.dist < y.dist : x.v < y.v;
        });
        std::vector<std::vector<size_t>> incident(m_pos.size());
        for (size_t f = 0; f < m_tris.size(); ++f)
            for (int32_t v : m_tris[f])
                incident[size_t(v)].push_back(f);
        size_t moved = 0;
        for (const Candidate& c : list) {
            if (m_chart[size_t(c.v)] < 0) continue;
            if (c.dist <= 1e-9 * (c.to.norm() + 1e-3)) { // already on the border (a cut mesh cut again)
                m_chart[size_t(c.v)] = -1;
                ++moved;
                continue;
            }
            if (!canMove(c.v, c.to, incident[size_t(c.v)])) continue;
            m_pos[size_t(c.v)] = c.to;
            m_chart[size_t(c.v)] = -1;
            m_border.clear(); // the crossings next to it moved
            ++moved;
        }
        return moved;
    }

    /// The cut mesh (dead triangles and unused vertices dropped), its chart borders and, among
    /// them, the seam edges.
    UvMesh finish() {
        std::vector<int32_t> remap(m_pos.size(), -1);
        std::vector<Vec3> pos;
        std::vector<sim::Tri> tris;
        std::vector<int> charts;
        for (size_t f = 0; f < m_tris.size(); ++f) {
            sim::Tri t = m_tris[f];
            for (int32_t& v : t) {
                if (remap[size_t(v)] < 0) {
                    remap[size_t(v)] = int32_t(pos.size());
                    pos.push_back(m_pos[size_t(v)]);
                }
                v = remap[size_t(v)];
            }
            tris.push_back(t);
            charts.push_back(m_pieceChart[f]);
        }
        std::unordered_map<uint64_t, std::vector<size_t>> faces;
        for (size_t f = 0; f < tris.size(); ++f)
            for (int k = 0; k < 3; ++k)
                faces[edgeKey(tris[f][k], tris[f][(k + 1) % 3])].push_back(f);
        std::vector<uint64_t> keys;
        for (const auto& [key, list] : faces)
            if (list.size() == 2 && charts[list[0]] != charts[list[1]]) keys.push_back(key);
        std::sort(keys.begin(), keys.end());
        UvMesh out;
        auto centroid = [&](size_t f) { return Vec3((pos[tris[f][0]] + pos[tris[f][1]] + pos[tris[f][2]]) / 3.0); };
        for (uint64_t key : keys) {
            const int32_t a = int32_t(key >> 32), b = int32_t(key & 0xffffffffu);
            out.chartBorders.push_back({a, b});
            if (isSeamEdge(m_src, pos[a], pos[b], centroid(faces[key][0]), centroid(faces[key][1])))
                out.seamEdges.push_back({a, b});
        }
        out.mesh = sim::TriMesh::fromArrays(std::move(pos), std::move(tris), "seam cut");
        return out;
    }

private:
    int chartAt(const Vec3& x) const { return m_src.chart(m_src.closest(x).triangle); }

    int32_t addVertex(const Vec3& x, int chart) {
        m_pos.push_back(x);
        m_chart.push_back(chart);
        return int32_t(m_pos.size() - 1);
    }

    std::vector<std::array<int32_t, 2>> edges() const {
        std::vector<std::array<int32_t, 2>> list;
        std::unordered_map<uint64_t, char> seen;
        for (const sim::Tri& t : m_tris)
            for (int k = 0; k < 3; ++k) {
                const int32_t a = std::min(t[k], t[(k + 1) % 3]), b = std::max(t[k], t[(k + 1) % 3]);
                if (seen.emplace(edgeKey(a, b), 1).second) list.push_back({a, b});
            }
        return list;
    }

    void piece(std::vector<sim::Tri>& out, const sim::Tri& t, int chart) {
        out.push_back(t);
        m_pieceChart.resize(out.size());
        m_pieceChart.back() = chart;
    }

    /// A triangle over two charts: the odd corner's piece and the quad of the other two, split
    /// along its shorter diagonal.
    template <class Mid>
    void splitTwo(std::vector<sim::Tri>& out, const sim::Tri& t, const std::array<int, 3>& c, Mid mid) {
        const int odd = c[0] == c[1] ? 2 : c[1] == c[2] ? 0 : 1;
        const int32_t v0 = t[(odd + 1) % 3], v1 = t[(odd + 2) % 3], v2 = t[odd];
        const int32_t m12 = mid((odd + 2) % 3), m20 = mid(odd);
        piece(out, {m12, v2, m20}, m_chart[v2]);
        if ((m_pos[v0] - m_pos[m12]).squaredNorm() <= (m_pos[v1] - m_pos[m20]).squaredNorm()) {
            piece(out, {v0, v1, m12}, m_chart[v0]);
            piece(out, {v0, m12, m20}, m_chart[v0]);
        } else {
            piece(out, {v0, v1, m20}, m_chart[v0]);
            piece(out, {v1, m12, m20}, m_chart[v0]);
        }
    }

    /// A triangle over three charts: a vertex at the mean of its three cut points, and two pieces
    /// at each corner (the quad corner, cut point, centre, cut point).
    void splitThree(std::vector<sim::Tri>& out, const sim::Tri& t, const std::array<int, 3>& c,
                    const std::array<int32_t, 3>& m) {
        const int32_t z = addVertex((m_pos[m[0]] + m_pos[m[1]] + m_pos[m[2]]) / 3.0, -1);
        for (int k = 0; k < 3; ++k) { // corner k lies between cut points m[k] (edge k) and m[k − 1]
            piece(out, {t[k], m[k], z}, c[k]);
            piece(out, {t[k], z, m[(k + 2) % 3]}, c[k]);
        }
    }

    /// The border fraction on edge (a, b), a < b, between their two charts (cached).
    double border(int32_t a, int32_t b) {
        const auto [it, fresh] = m_border.try_emplace(edgeKey(a, b), 0.0);
        if (fresh) it->second = chartBorder(m_src, m_chart[a], m_chart[b], m_pos[a], m_pos[b]);
        return it->second;
    }

    /// Whether vertex v may move to `to`: its neighbours on at most two charts (the border it
    /// moves onto is theirs; a neighbour already on it counts for none) and no triangle around
    /// it folding.
    bool canMove(int32_t v, const Vec3& to, const std::vector<size_t>& around) const {
        std::set<int> charts{m_chart[size_t(v)]};
        for (size_t f : around) {
            const sim::Tri& t = m_tris[f];
            const int k = t[0] == v ? 0 : t[1] == v ? 1 : 2;
            for (int j = 1; j < 3; ++j) {
                const int c = m_chart[size_t(t[(k + j) % 3])];
                if (c >= 0) charts.insert(c);
            }
            const Vec3 &b = m_pos[size_t(t[(k + 1) % 3])], &c = m_pos[size_t(t[(k + 2) % 3])];
            const Vec3 before = (b - m_pos[size_t(v)]).cross(c - m_pos[size_t(v)]), after = (b - to).cross(c - to);
            if (!(after.dot(before) > 0.1 * before.squaredNorm())) return false;
        }
        return charts.size() <= 2;
    }

    const UvSource& m_src;
    std::vector<Vec3> m_pos;
    std::vector<sim::Tri> m_tris;
    std::vector<int> m_chart;      ///< per vertex: its chart, −1 on a border (snapped, or a cut point)
    std::vector<int> m_pieceChart; ///< per triangle after the cut
    std::unordered_map<uint64_t, double> m_border; ///< edge → border fraction, for the current positions
};

} // namespace

bool isSeamEdge(const UvSource& source, const Vec3& a, const Vec3& b, const Vec3& c0, const Vec3& c1) {
    const double len = (b - a).norm();
    const Vec3 m = source.closest(0.5 * (a + b)).point;
    if (source.distanceToSeam(m, len) <= 0.2 * len + 1e-9) return true;
    return source.island(source.closest(c0).triangle) != source.island(source.closest(c1).triangle);
}

UvMesh cutAlongSeams(const UvSource& source, const sim::TriMesh& target, const SeamCutParams& params,
                     SeamCutReport* reportOut) {
    if (!(params.snapFraction >= 0 && params.snapFraction <= 0.45))
        throw std::invalid_argument("bake::cutAlongSeams(): SeamCutParams::snapFraction must be in [0, 0.45]");
    if (params.refineRounds < 0 || params.refineRounds > 8)
        throw std::invalid_argument("bake::cutAlongSeams(): SeamCutParams::refineRounds must be in [0, 8]");
    SeamCutReport report;
    SeamCutter cutter(source, target);
    size_t thirdLeft = 0; // edges still over a third chart: their pieces are found below
    report.refinedEdges = cutter.refine(params.refineRounds, thirdLeft);
    report.snappedVertices = cutter.snap(params.snapFraction);
    for (int pass = 0;; ++pass) {
        size_t crossed = 0;
        report.splitTriangles += cutter.cut(crossed);
        report.crossedEdges += crossed;
        const size_t stray = cutter.splitStrayPieces(pass < params.refineRounds);
        if (stray == 0 || pass == params.refineRounds) {
            report.unresolvedPieces += stray;
            break;
        }
        report.refinedEdges += stray;
    }
    UvMesh out = cutter.finish();
    report.seamEdges = out.seamEdges.size();
    if (reportOut) *reportOut = report;
    return out;
}

} // namespace viscera::bake
