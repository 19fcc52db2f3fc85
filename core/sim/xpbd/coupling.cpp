#include "sim/xpbd/coupling.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace viscera::sim {
namespace {

/// Uniform grid over element bounding boxes; query by box. Build O(#elements · cells per box).
class BoxGrid {
public:
    BoxGrid(const std::vector<Eigen::AlignedBox3d>& boxes, double pad) {
        Eigen::AlignedBox3d all;
        double extent = 0;
        for (const auto& b : boxes) {
            all.extend(b);
            extent += (b.max() - b.min()).maxCoeff();
        }
        all.min().array() -= pad;
        all.max().array() += pad;
        m_origin = all.min();
        const double cell = std::max(extent / std::max<size_t>(boxes.size(), 1), 1e-9);
        const Vec3 size = all.max() - all.min();
        for (int a = 0; a < 3; ++a)
            m_dims[a] = std::clamp(static_cast<int>(std::ceil(size[a] / cell)), 1, 256);
        for (int a = 0; a < 3; ++a)
            m_cell[a] = std::max(size[a] / m_dims[a], 1e-12);
        m_start.assign(static_cast<size_t>(m_dims[0]) * m_dims[1] * m_dims[2] + 1, 0);
        // Two passes: count, then fill (CSR).
        for (int pass = 0; pass < 2; ++pass) {
            std::vector<int32_t> fill;
            if (pass == 1) {
                for (size_t c = 1; c < m_start.size(); ++c)
                    m_start[c] += m_start[c - 1];
                m_items.resize(m_start.back());
                fill.assign(m_start.begin(), m_start.end() - 1);
            }
            for (size_t e = 0; e < boxes.size(); ++e) {
                std::array<int, 3> lo, hi;
                range(boxes[e].min(), boxes[e].max(), lo, hi);
                for (int i = lo[0]; i <= hi[0]; ++i)
                    for (int j = lo[1]; j <= hi[1]; ++j)
                        for (int k = lo[2]; k <= hi[2]; ++k) {
                            const size_t c = index(i, j, k);
                            if (pass == 0)
                                ++m_start[c + 1];
                            else
                                m_items[fill[c]++] = static_cast<int32_t>(e);
                        }
            }
        }
        m_stamp.assign(boxes.size(), -1);
    }

    /// Elements whose cells overlap the box [lo, hi], each once, into out.
    void query(const Vec3& lo, const Vec3& hi, std::vector<int32_t>& out) {
        out.clear();
        ++m_query;
        std::array<int, 3> a, b;
        range(lo, hi, a, b);
        for (int i = a[0]; i <= b[0]; ++i)
            for (int j = a[1]; j <= b[1]; ++j)
                for (int k = a[2]; k <= b[2]; ++k) {
                    const size_t c = index(i, j, k);
                    for (int32_t n = m_start[c]; n < m_start[c + 1]; ++n) {
                        const int32_t e = m_items[n];
                        if (m_stamp[e] == m_query) continue;
                        m_stamp[e] = m_query;
                        out.push_back(e);
                    }
                }
    }

private:
    void range(const Vec3& lo, const Vec3& hi, std::array<int, 3>& a, std::array<int, 3>& b) const {
        for (int d = 0; d < 3; ++d) {
            a[d] = std::clamp(static_cast<int>(std::floor((lo[d] - m_origin[d]) / m_cell[d])), 0, m_dims[d] - 1);
            b[d] = std::clamp(static_cast<int>(std::floor((hi[d] - m_origin[d]) / m_cell[d])), 0, m_dims[d] - 1);
        }
    }
    size_t index(int i, int j, int k) const { return (static_cast<size_t>(k) * m_dims[1] + j) * m_dims[0] + i; }

    Vec3 m_origin;
    std::array<int, 3> m_dims{};
    std::array<double, 3> m_cell{};
    std::vector<int32_t> m_start, m_items;
    std::vector<int64_t> m_stamp;
    int64_t m_query = 0;
};

} // namespace

Vec3 couplingResidual(const Vec3& xp, const Vec3* targets, const double* bary, int n) {
    Vec3 c = xp;
    for (int k = 0; k < n; ++k)
        c -= bary[k] * targets[k];
    return c;
}

Vec3 closestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, Eigen::Vector3d& bary) {
    // Voronoi-region walk (Ericson, Real-Time Collision Detection §5.1.5).
    const Vec3 ab = b - a, ac = c - a, ap = p - a;
    const double d1 = ab.dot(ap), d2 = ac.dot(ap);
    if (d1 <= 0 && d2 <= 0) {
        bary = {1, 0, 0};
        return a;
    }
    const Vec3 bp = p - b;
    const double d3 = ab.dot(bp), d4 = ac.dot(bp);
    if (d3 >= 0 && d4 <= d3) {
        bary = {0, 1, 0};
        return b;
    }
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        const double v = d1 / (d1 - d3);
        bary = {1 - v, v, 0};
        return a + v * ab;
    }
    const Vec3 cp = p - c;
    const double d5 = ab.dot(cp), d6 = ac.dot(cp);
    if (d6 >= 0 && d5 <= d6) {
        bary = {0, 0, 1};
        return c;
    }
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        const double w = d2 / (d2 - d6);
        bary = {1 - w, 0, w};
        return a + w * ac;
    }
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
        const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        bary = {0, 1 - w, w};
        return b + w * (c - b);
    }
    const double denom = 1.0 / (va + vb + vc);
    const double v = vb * denom, w = vc * denom;
    bary = {1 - v - w, v, w};
    return a + ab * v + ac * w;
}

std::vector<BoundaryProjection> projectOntoBoundary(const TetMesh& cage, const std::vector<Vec3>& points,
                                                    double maxDistance) {
    if (!(maxDistance >= 0) || !std::isfinite(maxDistance))
        throw std::invalid_argument("sim::projectOntoBoundary(): maxDistance must be finite and >= 0");
    const auto& x = cage.positions();
    std::vector<std::array<int32_t, 3>> tris;
    for (int32_t f = 0; f < static_cast<int32_t>(4 * cage.tetCount()); ++f)
        if (cage.isBoundaryHalfFacet(f)) tris.push_back(cage.halfFacetVertices(f));
    std::vector<Eigen::AlignedBox3d> boxes;
    boxes.reserve(tris.size());
    for (const auto& t : tris) {
        Eigen::AlignedBox3d b(x[t[0]]);
        b.extend(x[t[1]]);
        b.extend(x[t[2]]);
        boxes.push_back(b);
    }
    std::vector<BoundaryProjection> out;
    if (tris.empty()) return out;
    BoxGrid grid(boxes, maxDistance);
    std::vector<int32_t> cand;
    const Vec3 r = Vec3::Constant(maxDistance);
    for (size_t i = 0; i < points.size(); ++i) {
        grid.query(points[i] - r, points[i] + r, cand);
        BoundaryProjection best;
        best.distance = std::numeric_limits<double>::infinity();
        for (int32_t t : cand) {
            Eigen::Vector3d bary;
            const Vec3 q = closestPointOnTriangle(points[i], x[tris[t][0]], x[tris[t][1]], x[tris[t][2]], bary);
            const double d = (q - points[i]).norm();
            if (d < best.distance) {
                best.distance = d;
                best.vertices = tris[t];
                best.bary = bary;
            }
        }
        if (best.distance <= maxDistance) {
            best.point = static_cast<int32_t>(i);
            out.push_back(best);
        }
    }
    return out;
}

std::vector<CageLocation> locateInCage(const TetMesh& cage, const std::vector<Vec3>& points, double tolerance) {
    const std::string where = "sim::locateInCage(): ";
    if (!(tolerance >= 0) || !std::isfinite(tolerance))
        throw std::invalid_argument(where + "tolerance must be finite and >= 0");
    const auto& x = cage.positions();
    const auto& tets = cage.tets();
    std::vector<Eigen::AlignedBox3d> boxes;
    boxes.reserve(tets.size());
    for (const Tet& e : tets) {
        Eigen::AlignedBox3d b(x[e[0]]);
        for (int k = 1; k < 4; ++k)
            b.extend(x[e[k]]);
        boxes.push_back(b);
    }
    BoxGrid grid(boxes, tolerance);
    std::vector<CageLocation> out;
    out.reserve(points.size());
    std::vector<int32_t> cand;
    const Vec3 r = Vec3::Constant(tolerance);
    static const int kFace[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
    for (size_t i = 0; i < points.size(); ++i) {
        const Vec3& p = points[i];
        grid.query(p - r, p + r, cand);
        CageLocation best;
        double bestDist = std::numeric_limits<double>::infinity();
        double bestMin = -std::numeric_limits<double>::infinity();
        for (int32_t t : cand) {
            if (boxes[t].exteriorDistance(p) > tolerance) continue;
            const Eigen::Vector4d b = cage.barycentric(t, p);
            const double minB = b.minCoeff();
            double dist = 0;
            if (minB < 0) {
                dist = std::numeric_limits<double>::infinity();
                for (const auto& f : kFace) {
                    Eigen::Vector3d fb;
                    const Vec3 q = closestPointOnTriangle(p, x[tets[t][f[0]]], x[tets[t][f[1]]], x[tets[t][f[2]]], fb);
                    dist = std::min(dist, (q - p).norm());
                }
            }
            if (dist < bestDist || (dist == bestDist && minB > bestMin)) {
                bestDist = dist;
                bestMin = minB;
                best.tet = t;
                best.bary = b;
            }
        }
        if (best.tet < 0 || bestDist > tolerance) {
            const std::string howFar = best.tet < 0
                                           ? "lies more than " + std::to_string(tolerance) + " m outside the cage"
                                           : "lies " + std::to_string(bestDist) + " m outside the cage";
            throw OutsideCageError(where, static_cast<int32_t>(i), howFar);
        }
        best.point = static_cast<int32_t>(i);
        out.push_back(best);
    }
    return out;
}

} // namespace viscera::sim
