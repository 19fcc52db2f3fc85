#include "sim/suture/tip_tracking.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace viscera::sim {
namespace {

Vec3 faceNormal(const std::vector<Vec3>& x, const std::array<int32_t, 3>& v) {
    return (x[v[1]] - x[v[0]]).cross(x[v[2]] - x[v[0]]);
}

} // namespace

TipTracker::TipTracker(const TetMesh& mesh) : m_mesh(mesh) {
    if (mesh.level() < 3)
        throw std::logic_error("sim::TipTracker(): requires adjacency level 3; call mesh.requireLevel(3) first");
    double sum = 0;
    size_t k = 0;
    const auto& x = mesh.positions();
    for (const Tet& t : mesh.tets()) {
        sum += (x[t[1]] - x[t[0]]).norm() + (x[t[2]] - x[t[0]]).norm() + (x[t[3]] - x[t[0]]).norm();
        k += 3;
    }
    m_h = k ? sum / static_cast<double>(k) : 1.0;
    m_epsS = 1e-10 * m_h;
}

Eigen::Vector4d TipTracker::barycentric(const std::vector<Vec3>& x, int32_t t, const Vec3& p) const {
    const Tet& e = m_mesh.tets()[t];
    const Vec3 &a = x[e[0]], &b = x[e[1]], &c = x[e[2]], &d = x[e[3]];
    const double v = (b - a).dot((c - a).cross(d - a));
    Eigen::Vector4d l;
    l[1] = (p - a).dot((c - a).cross(d - a)) / v;
    l[2] = (b - a).dot((p - a).cross(d - a)) / v;
    l[3] = (b - a).dot((c - a).cross(p - a)) / v;
    l[0] = 1.0 - l[1] - l[2] - l[3];
    return l;
}

void TipTracker::faceBary(const std::vector<Vec3>& x, int32_t f, const Vec3& p, Vec3& xi) const {
    const auto v = m_mesh.halfFacetVertices(f);
    const Vec3 &a = x[v[0]], &b = x[v[1]], &c = x[v[2]];
    const Vec3 n = (b - a).cross(c - a);
    const double nn = n.squaredNorm();
    if (!(nn > 0)) {
        xi = Vec3::Constant(1.0 / 3.0);
        return;
    }
    xi[0] = (c - b).cross(p - b).dot(n) / nn;
    xi[1] = (a - c).cross(p - c).dot(n) / nn;
    xi[2] = 1.0 - xi[0] - xi[1];
}

int32_t TipTracker::locate(const std::vector<Vec3>& x, const Vec3& p) const {
    int32_t best = kNone;
    double bestMin = -m_epsB;
    for (int32_t t = 0; t < static_cast<int32_t>(m_mesh.tetCount()); ++t) {
        const double mn = barycentric(x, t, p).minCoeff();
        if (mn >= bestMin) {
            bestMin = mn;
            best = t;
        }
    }
    return best;
}

TipTracker::Exit TipTracker::exitOf(const std::vector<Vec3>& x, const NeedleCurve& c, int32_t t, double s,
                                    double b) const {
    Exit ex;
    ex.alpha = std::numeric_limits<double>::infinity();
    double roots[8];
    for (int i = 0; i < 4; ++i) {
        const auto v = m_mesh.halfFacetVertices(4 * t + i);
        Vec3 n = faceNormal(x, v);
        const double len = n.norm();
        if (!(len > 0)) continue;
        n /= len;
        const int k = c.planeCrossings(n, n.dot(x[v[0]]), s + m_epsS, b, roots, 8);
        for (int r = 0; r < k; ++r)
            if (n.dot(c.tangent(roots[r])) > 0 && roots[r] < ex.alpha) {
                ex.alpha = roots[r];
                ex.face = i;
                ex.found = true;
                break; // ascending: the first exit through this plane
            }
    }
    return ex;
}

int32_t TipTracker::chooseNext(const std::vector<Vec3>& x, const NeedleCurve& c, const std::vector<int32_t>& cands,
                               int32_t from, double s, double b) const {
    int32_t best = kNone;
    double bestScore = -1e-3 / m_h; // tolerance on a barycentric rate (1/m)
    for (int32_t cell : cands) {
        if (cell == from || cell == kNone) continue;
        const Exit ex = exitOf(x, c, cell, s, b);
        const double end = ex.found ? std::min(ex.alpha, b) : b;
        if (!(end > s + m_epsS)) continue;
        // The path must lie in the cell right after s (an arc may enter a candidate later, through
        // one of its other facets): probe just past s, and keep the most interior candidate.
        const double delta = std::min(1e-6 * m_h, 0.5 * (end - s));
        const double score = barycentric(x, cell, c.point(s + delta)).minCoeff() / delta;
        if (score > bestScore) {
            bestScore = score;
            best = cell;
        }
    }
    return best;
}

int32_t TipTracker::track(const std::vector<Vec3>& x, const NeedleCurve& c, double a, double b, int32_t cell,
                          std::vector<Crossing>& out, const TrackOptions& opt, double* stoppedAt) const {
    double s = a;
    int32_t t = cell;
    std::vector<int32_t> link, cands;
    const auto& bhf = m_mesh.boundaryHalfFacets();
    double roots[8];
    for (int guard = 0; guard < opt.maxCrossings && s < b; ++guard) {
        Crossing cr;
        cr.fromCell = t;
        int32_t vertexA = kNone, vertexB = kNone; // edge / vertex of an edge or vertex crossing
        Vec3 P;
        if (t == kNone) {
            // ⊥: the first boundary facet the curve enters through [B Alg. 3.2, r32(⊥)].
            double best = std::numeric_limits<double>::infinity();
            int32_t bestF = kNone;
            for (int32_t f : bhf) {
                const auto v = m_mesh.halfFacetVertices(f);
                Vec3 n = faceNormal(x, v);
                const double len = n.norm();
                if (!(len > 0)) continue;
                n /= len;
                const int k = c.planeCrossings(n, n.dot(x[v[0]]), s + m_epsS, std::min(b, best), roots, 8);
                for (int r = 0; r < k; ++r) {
                    if (!(n.dot(c.tangent(roots[r])) < 0)) continue;
                    Vec3 xi;
                    faceBary(x, f, c.point(roots[r]), xi);
                    if (xi.minCoeff() >= -m_epsB) {
                        if (roots[r] < best) {
                            best = roots[r];
                            bestF = f;
                        }
                        break;
                    }
                }
            }
            if (bestF == kNone) break;
            cr.alpha = best;
            P = c.point(best);
            cr.face = bestF;
            faceBary(x, bestF, P, cr.xi);
            const auto v = m_mesh.halfFacetVertices(bestF);
            int zeros = 0, keep[3], nk = 0;
            for (int i = 0; i < 3; ++i) {
                if (cr.xi[i] <= m_epsB)
                    ++zeros;
                else
                    keep[nk++] = v[i];
            }
            if (zeros == 0) {
                cr.kind = CrossingKind::Face;
                cr.toCell = TetMesh::cellOf(bestF);
            } else {
                cr.kind = zeros == 1 ? CrossingKind::Edge : CrossingKind::Vertex;
                vertexA = keep[0];
                vertexB = zeros == 1 ? keep[1] : kNone;
            }
        } else {
            const Exit ex = exitOf(x, c, t, s, b);
            if (!ex.found || ex.alpha > b) break; // the walk ends inside t
            cr.alpha = ex.alpha;
            P = c.point(ex.alpha);
            const Eigen::Vector4d l = barycentric(x, t, P);
            const Tet& T = m_mesh.tets()[t];
            int zeros = 0, keep[4], nk = 0;
            for (int i = 0; i < 4; ++i) {
                if (i == ex.face || l[i] <= m_epsB)
                    ++zeros;
                else
                    keep[nk++] = T[i];
            }
            if (zeros == 1) {
                cr.kind = CrossingKind::Face;
                const int32_t f = 4 * t + ex.face, o = m_mesh.opp(f);
                cr.toCell = o == kNone ? kNone : TetMesh::cellOf(o);
                cr.face = o == kNone ? f : o;
                faceBary(x, cr.face, P, cr.xi);
            } else {
                cr.kind = zeros == 2 ? CrossingKind::Edge : CrossingKind::Vertex;
                vertexA = keep[0];
                vertexB = zeros == 2 ? keep[1] : kNone;
            }
        }
        if (cr.kind != CrossingKind::Face) {
            // Through an edge or a vertex: the next cell is among those of its face link.
            if (cr.kind == CrossingKind::Edge) {
                const int32_t e = m_mesh.findEdge(vertexA, vertexB);
                link.clear();
                if (e != kNone) m_mesh.linkFacetsOfEdgeInto(m_mesh.edgeHalfEdge(e), link);
            } else {
                m_mesh.linkFacetsOfVertexInto(vertexA, link);
            }
            cands.clear();
            for (int32_t f : link)
                cands.push_back(TetMesh::cellOf(f));
            std::sort(cands.begin(), cands.end());
            cands.erase(std::unique(cands.begin(), cands.end()), cands.end());
            cr.toCell = chooseNext(x, c, cands, t, cr.alpha, b);
            // The facet carrying P: the entered cell's facet nearest to P, or t's boundary facet.
            const int32_t holder = cr.toCell != kNone ? cr.toCell : t;
            if (holder != kNone) {
                const Eigen::Vector4d l = barycentric(x, holder, P);
                int best = 0;
                for (int i = 1; i < 4; ++i) {
                    const bool bi = cr.toCell == kNone && m_mesh.opp(4 * holder + i) == kNone;
                    const bool bb = cr.toCell == kNone && m_mesh.opp(4 * holder + best) == kNone;
                    if ((bi && !bb) || (bi == bb && std::abs(l[i]) < std::abs(l[best]))) best = i;
                }
                cr.face = 4 * holder + best;
            }
            if (cr.face != kNone) faceBary(x, cr.face, P, cr.xi);
        }
        cr.xi = cr.xi.cwiseMax(0.0);
        const double sum = cr.xi.sum();
        cr.xi = sum > 0 ? Vec3(cr.xi / sum) : Vec3::Constant(1.0 / 3.0);
        out.push_back(cr);
        s = cr.alpha;
        t = cr.toCell;
        if (opt.stopAtBoundary && cr.boundary()) {
            if (stoppedAt) *stoppedAt = s;
            return t;
        }
    }
    if (stoppedAt) *stoppedAt = b;
    return t;
}

} // namespace viscera::sim
