#include "sim/mesh/tet_mesh.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace viscera::sim {
namespace {

/// Local vertices of half-facet i in outward counter-clockwise order [B Table 2.1].
constexpr int kFace[4][3] = {{1, 2, 3}, {2, 0, 3}, {3, 0, 1}, {0, 2, 1}};

/// Relative orientation of half-edges in a cell [B eq. 2.17]: kP[a][f] is the local vertex that
/// follows local vertex a in half-facet f, and kP[f][a] the one that precedes it.
constexpr int kP[4][4] = {{-1, 3, 1, 2}, {2, -1, 3, 0}, {3, 0, -1, 1}, {1, 2, 0, -1}};

/// The six local edges of a tet and, for each, the two half-facets that contain it.
constexpr int kEdge[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
constexpr int kEdgeFaces[6][2] = {{2, 3}, {1, 3}, {1, 2}, {0, 3}, {0, 2}, {0, 1}};

double tetVolume(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
    return (b - a).dot((c - a).cross(d - a)) / 6.0;
}

bool containsValue(const std::vector<int32_t>& v, int32_t x) {
    return std::find(v.begin(), v.end(), x) != v.end();
}

} // namespace

std::unique_ptr<TetMesh> TetMesh::fromArrays(std::vector<Vec3> positions, std::vector<Tet> tets,
                                             const std::string& origin) {
    if (tets.empty()) throw std::invalid_argument(origin + ": mesh has no tets");
    if (tets.size() > (size_t{1} << 29)) throw std::invalid_argument(origin + ": mesh has more than 2^29 tets");
    for (size_t v = 0; v < positions.size(); ++v)
        if (!positions[v].allFinite())
            throw std::invalid_argument(origin + ": vertex " + std::to_string(v) + " has a non-finite coordinate");
    const auto n = static_cast<int64_t>(positions.size());
    for (size_t t = 0; t < tets.size(); ++t) {
        const Tet& e = tets[t];
        for (int k = 0; k < 4; ++k)
            if (e[k] < 0 || e[k] >= n)
                throw std::invalid_argument(origin + ": tet " + std::to_string(t) + " references vertex " +
                                            std::to_string(e[k]) + " (mesh has " + std::to_string(n) + " vertices)");
        for (int a = 0; a < 4; ++a)
            for (int b = a + 1; b < 4; ++b)
                if (e[a] == e[b])
                    throw std::invalid_argument(origin + ": tet " + std::to_string(t) + " repeats vertex " +
                                                std::to_string(e[a]));
    }
    std::unique_ptr<TetMesh> m(new TetMesh());
    m->m_positions = std::move(positions);
    m->m_tets = std::move(tets);
    m->buildLevel1(origin);
    return m;
}

std::unique_ptr<TetMesh> TetMesh::clone() const {
    std::unique_ptr<TetMesh> m(new TetMesh());
    m->m_positions = m_positions;
    m->m_tets = m_tets;
    m->m_level = m_level;
    m->m_opp = m_opp;
    m->m_facetHf = m_facetHf;
    m->m_hfFacet = m_hfFacet;
    m->m_edgeHe = m_edgeHe;
    m->m_edgeVerts = m_edgeVerts;
    m->m_vertEdgeStart = m_vertEdgeStart;
    m->m_vertHf = m_vertHf;
    m->m_boundary = m_boundary;
    m->m_boundaryHf = m_boundaryHf;
    m->m_boundaryVerts = m_boundaryVerts;
    return m;
}

std::array<int32_t, 3> TetMesh::halfFacetVertices(int32_t f) const {
    const Tet& t = m_tets[f >> 2];
    const int* l = kFace[f & 3];
    return {t[l[0]], t[l[1]], t[l[2]]};
}

double TetMesh::signedVolume(int32_t t) const {
    const Tet& e = m_tets[t];
    return tetVolume(m_positions[e[0]], m_positions[e[1]], m_positions[e[2]], m_positions[e[3]]);
}

Eigen::Vector4d TetMesh::barycentric(int32_t t, const Vec3& p) const {
    // Cramer's rule [B eq. 2.3]: xi_i = vol(tet with v_i replaced by p) / vol(tet).
    const Tet& e = m_tets[t];
    const Vec3* v[4] = {&m_positions[e[0]], &m_positions[e[1]], &m_positions[e[2]], &m_positions[e[3]]};
    const double vol = tetVolume(*v[0], *v[1], *v[2], *v[3]);
    Eigen::Vector4d xi;
    for (int i = 0; i < 4; ++i) {
        const Vec3* w[4] = {v[0], v[1], v[2], v[3]};
        w[i] = &p;
        xi[i] = tetVolume(*w[0], *w[1], *w[2], *w[3]) / vol;
    }
    return xi;
}

HalfEdge TetMesh::heNext(HalfEdge e) {
    const int32_t base = e.f & ~3;
    return {e.f, base + kP[e.v & 3][e.f & 3]};
}

HalfEdge TetMesh::hePrev(HalfEdge e) {
    const int32_t base = e.f & ~3;
    return {e.f, base + kP[e.f & 3][e.v & 3]};
}

HalfEdge TetMesh::heMate(HalfEdge e) {
    return {hePrev(e).v, heNext(e).v};
}

HalfEdge TetMesh::heRadial(HalfEdge e) const {
    requireAtLeast(1, "heRadial");
    const int32_t g = m_opp[e.f];
    if (g == kNone) return {kNone, kNone};
    // The radial half-edge runs along the same edge in the opposite direction, so it starts at
    // the end vertex of e.
    const int32_t end = vertex(heNext(e).v);
    const int32_t base = g & ~3;
    const Tet& t = m_tets[g >> 2];
    for (int i = 0; i < 4; ++i)
        if (t[i] == end) return {g, base + i};
    return {kNone, kNone}; // unreachable for a valid level-1 mesh
}

std::array<int32_t, 2> TetMesh::halfEdgeVertices(HalfEdge e) const {
    return {vertex(e.v), vertex(heNext(e).v)};
}

void TetMesh::requireAtLeast(int level, const char* query) const {
    if (m_level < level)
        throw std::logic_error(std::string("sim::TetMesh::") + query + "(): requires adjacency level " +
                               std::to_string(level) + "; call requireLevel(" + std::to_string(level) + ") first");
}

int32_t TetMesh::opp(int32_t f) const {
    requireAtLeast(1, "opp");
    return m_opp[f];
}

std::array<int32_t, 4> TetMesh::adjacentCells(int32_t t) const {
    requireAtLeast(1, "adjacentCells");
    std::array<int32_t, 4> out;
    for (int i = 0; i < 4; ++i) {
        int32_t g = m_opp[4 * t + i];
        out[i] = g == kNone ? kNone : cellOf(g);
    }
    return out;
}

void TetMesh::buildLevel1(const std::string& origin) {
    struct Key {
        std::array<int32_t, 3> v;
        int32_t hf;
    };
    const auto nhf = static_cast<int32_t>(4 * m_tets.size());
    std::vector<Key> keys(nhf);
    for (int32_t f = 0; f < nhf; ++f) {
        auto v = halfFacetVertices(f);
        std::sort(v.begin(), v.end());
        keys[f] = {v, f};
    }
    std::sort(keys.begin(), keys.end(),
              [](const Key& a, const Key& b) { return a.v != b.v ? a.v < b.v : a.hf < b.hf; });
    m_opp.assign(nhf, kNone);
    for (int32_t i = 0; i < nhf;) {
        int32_t j = i + 1;
        while (j < nhf && keys[j].v == keys[i].v)
            ++j;
        if (j - i > 2)
            throw std::invalid_argument(origin + ": facet (" + std::to_string(keys[i].v[0]) + ", " +
                                        std::to_string(keys[i].v[1]) + ", " + std::to_string(keys[i].v[2]) +
                                        ") is shared by " + std::to_string(j - i) +
                                        " tets (non-manifold; at most 2 allowed)");
        if (j - i == 2) {
            m_opp[keys[i].hf] = keys[i + 1].hf;
            m_opp[keys[i + 1].hf] = keys[i].hf;
        }
        i = j;
    }
    m_level = 1;
}

void TetMesh::requireLevel(int level) {
    if (level < 0 || level > 3)
        throw std::invalid_argument("sim::TetMesh::requireLevel(): level " + std::to_string(level) +
                                    " is not in [0, 3]");
    if (level >= 2 && m_level < 2) buildLevel2();
    if (level >= 3 && m_level < 3) buildLevel3();
}

void TetMesh::buildLevel2() {
    const auto nhf = static_cast<int32_t>(4 * m_tets.size());
    // Facets: one per interior pair, one per boundary half-facet.
    m_hfFacet.assign(nhf, kNone);
    m_facetHf.clear();
    for (int32_t f = 0; f < nhf; ++f) {
        const int32_t g = m_opp[f];
        if (g == kNone || f < g) {
            const auto id = static_cast<int32_t>(m_facetHf.size());
            m_facetHf.push_back(f);
            m_hfFacet[f] = id;
            if (g != kNone) m_hfFacet[g] = id;
        }
    }
    // Edges: sorted unique vertex pairs; the representative half-edge prefers a boundary one.
    struct EdgeKey {
        int32_t a, b;
        HalfEdge he;
    };
    std::vector<EdgeKey> keys;
    keys.reserve(12 * m_tets.size());
    for (int32_t t = 0; t < static_cast<int32_t>(m_tets.size()); ++t) {
        const Tet& e = m_tets[t];
        for (int k = 0; k < 6; ++k) {
            const int i = kEdge[k][0], j = kEdge[k][1];
            for (int s = 0; s < 2; ++s) {
                const int face = kEdgeFaces[k][s];
                // In `face`, the half-edge starting at i goes to kP[i][face]; pick the direction
                // that lies along (i, j).
                const int start = kP[i][face] == j ? i : j;
                keys.push_back({std::min(e[i], e[j]), std::max(e[i], e[j]), HalfEdge{4 * t + face, 4 * t + start}});
            }
        }
    }
    std::sort(keys.begin(), keys.end(), [](const EdgeKey& x, const EdgeKey& y) {
        if (x.a != y.a) return x.a < y.a;
        if (x.b != y.b) return x.b < y.b;
        return x.he.f < y.he.f;
    });
    m_edgeHe.clear();
    m_edgeVerts.clear();
    for (size_t i = 0; i < keys.size();) {
        size_t j = i;
        HalfEdge pick = keys[i].he;
        bool boundary = false;
        for (; j < keys.size() && keys[j].a == keys[i].a && keys[j].b == keys[i].b; ++j)
            if (!boundary && m_opp[keys[j].he.f] == kNone) {
                pick = keys[j].he;
                boundary = true;
            }
        m_edgeHe.push_back(pick);
        m_edgeVerts.push_back({keys[i].a, keys[i].b});
        i = j;
    }
    m_vertEdgeStart.assign(m_positions.size() + 1, 0);
    for (const auto& ev : m_edgeVerts)
        ++m_vertEdgeStart[ev[0] + 1];
    for (size_t v = 0; v < m_positions.size(); ++v)
        m_vertEdgeStart[v + 1] += m_vertEdgeStart[v];
    // Vertex -> half-facet, preferring boundary half-facets.
    m_vertHf.assign(m_positions.size(), kNone);
    for (int32_t f = 0; f < nhf; ++f) {
        const bool bnd = m_opp[f] == kNone;
        for (int32_t v : halfFacetVertices(f)) {
            int32_t& cur = m_vertHf[v];
            if (cur == kNone || (bnd && m_opp[cur] != kNone)) cur = f;
        }
    }
    m_level = 2;
}

void TetMesh::buildLevel3() {
    m_boundaryHf.clear();
    std::vector<int32_t> local(m_positions.size(), kNone);
    m_boundaryVerts.clear();
    std::vector<Tri> tris;
    for (int32_t f = 0; f < static_cast<int32_t>(m_opp.size()); ++f) {
        if (m_opp[f] != kNone) continue;
        m_boundaryHf.push_back(f);
        Tri tri;
        auto v = halfFacetVertices(f);
        for (int k = 0; k < 3; ++k) {
            if (local[v[k]] == kNone) {
                local[v[k]] = static_cast<int32_t>(m_boundaryVerts.size());
                m_boundaryVerts.push_back(v[k]);
            }
            tri[k] = local[v[k]];
        }
        tris.push_back(tri);
    }
    std::vector<Vec3> pos;
    pos.reserve(m_boundaryVerts.size());
    for (int32_t v : m_boundaryVerts)
        pos.push_back(m_positions[v]);
    m_boundary = TriMesh::fromArrays(std::move(pos), std::move(tris), "sim::TetMesh boundary");
    m_level = 3;
}

size_t TetMesh::facetCount() const {
    requireAtLeast(2, "facetCount");
    return m_facetHf.size();
}
size_t TetMesh::edgeCount() const {
    requireAtLeast(2, "edgeCount");
    return m_edgeHe.size();
}
int32_t TetMesh::facetHalfFacet(int32_t i) const {
    requireAtLeast(2, "facetHalfFacet");
    return m_facetHf[i];
}
int32_t TetMesh::facetOfHalfFacet(int32_t f) const {
    requireAtLeast(2, "facetOfHalfFacet");
    return m_hfFacet[f];
}
HalfEdge TetMesh::edgeHalfEdge(int32_t i) const {
    requireAtLeast(2, "edgeHalfEdge");
    return m_edgeHe[i];
}
std::array<int32_t, 2> TetMesh::edgeVertices(int32_t i) const {
    requireAtLeast(2, "edgeVertices");
    return m_edgeVerts[i];
}
int32_t TetMesh::findEdge(int32_t a, int32_t b) const {
    requireAtLeast(2, "findEdge");
    if (a > b) std::swap(a, b);
    if (a < 0 || b >= static_cast<int32_t>(m_positions.size())) return kNone;
    auto first = m_edgeVerts.begin() + m_vertEdgeStart[a];
    auto last = m_edgeVerts.begin() + m_vertEdgeStart[a + 1];
    auto it = std::lower_bound(first, last, std::array<int32_t, 2>{a, b});
    return (it != last && (*it)[1] == b) ? static_cast<int32_t>(it - m_edgeVerts.begin()) : kNone;
}
int32_t TetMesh::vertexHalfFacet(int32_t v) const {
    requireAtLeast(2, "vertexHalfFacet");
    return m_vertHf[v];
}
bool TetMesh::isBoundaryVertex(int32_t v) const {
    requireAtLeast(2, "isBoundaryVertex");
    return m_vertHf[v] != kNone && m_opp[m_vertHf[v]] == kNone;
}
bool TetMesh::isBoundaryEdge(int32_t i) const {
    requireAtLeast(2, "isBoundaryEdge");
    return m_opp[m_edgeHe[i].f] == kNone;
}

void TetMesh::cellsOfVertexInto(int32_t v, std::vector<int32_t>& out) const {
    requireAtLeast(2, "cellsOfVertexInto");
    out.clear();
    if (m_vertHf[v] == kNone) return;
    // Flood fill across the facets that contain v, starting from I[v].
    out.push_back(cellOf(m_vertHf[v]));
    for (size_t k = 0; k < out.size(); ++k) {
        const int32_t t = out[k];
        for (int i = 0; i < 4; ++i) {
            if (m_tets[t][i] == v) continue;
            const int32_t g = m_opp[4 * t + i];
            if (g != kNone && !containsValue(out, cellOf(g))) out.push_back(cellOf(g));
        }
    }
}

void TetMesh::starFacetsOfVertexInto(int32_t v, std::vector<int32_t>& out) const {
    std::vector<int32_t> cells;
    cellsOfVertexInto(v, cells);
    out.clear();
    for (int32_t t : cells)
        for (int i = 0; i < 4; ++i)
            out.push_back(4 * t + i);
}

void TetMesh::openStarFacetsOfVertexInto(int32_t v, std::vector<int32_t>& out) const {
    std::vector<int32_t> cells;
    cellsOfVertexInto(v, cells);
    out.clear();
    for (int32_t t : cells)
        for (int i = 0; i < 4; ++i)
            if (m_tets[t][i] != v) out.push_back(4 * t + i);
}

void TetMesh::linkFacetsOfVertexInto(int32_t v, std::vector<int32_t>& out) const {
    std::vector<int32_t> cells;
    cellsOfVertexInto(v, cells);
    out.clear();
    for (int32_t t : cells)
        for (int i = 0; i < 4; ++i)
            if (m_tets[t][i] == v) out.push_back(4 * t + i);
}

namespace {

/// EdgeSweep of [B Alg. 2.4/2.5]: alternates mate (same cell) and radial (next cell) from a,
/// calling visit(half-edge, mate) once per cell, until the boundary or the start is reached.
/// Returns false when it stopped at the boundary.
template <class Visit> bool edgeSweep(const TetMesh& m, HalfEdge a, int32_t stopF, Visit&& visit) {
    do {
        const HalfEdge mate = TetMesh::heMate(a);
        visit(a, mate);
        a = m.heRadial(mate);
    } while (a.valid() && a.f != stopF);
    return a.valid();
}

template <class Visit> void sweepEdge(const TetMesh& m, HalfEdge e, Visit&& visit) {
    if (edgeSweep(m, e, e.f, visit)) return;
    // e is on the boundary: sweep the other way, starting across e's own facet.
    const HalfEdge back = m.heRadial(e);
    if (back.valid()) edgeSweep(m, back, e.f, visit);
}

} // namespace

void TetMesh::openStarFacetsOfEdgeInto(HalfEdge e, std::vector<int32_t>& out) const {
    requireAtLeast(2, "openStarFacetsOfEdgeInto");
    out.clear();
    sweepEdge(*this, e, [&](HalfEdge a, HalfEdge mate) {
        out.push_back(a.f);
        out.push_back(mate.f);
    });
}

void TetMesh::linkFacetsOfEdgeInto(HalfEdge e, std::vector<int32_t>& out) const {
    requireAtLeast(2, "linkFacetsOfEdgeInto");
    out.clear();
    // The half-facet opposite a half-vertex has the same index (Table 2.1), so the facets opposite
    // the edge's start and end vertices in this cell are a.v and mate.v.
    sweepEdge(*this, e, [&](HalfEdge a, HalfEdge mate) {
        out.push_back(a.v);
        out.push_back(mate.v);
    });
}

void TetMesh::cellsOfEdgeInto(HalfEdge e, std::vector<int32_t>& out) const {
    requireAtLeast(2, "cellsOfEdgeInto");
    out.clear();
    sweepEdge(*this, e, [&](HalfEdge a, HalfEdge) { out.push_back(cellOf(a.f)); });
}

const TriMesh& TetMesh::boundary() const {
    requireAtLeast(3, "boundary");
    return m_boundary;
}
const std::vector<int32_t>& TetMesh::boundaryHalfFacets() const {
    requireAtLeast(3, "boundaryHalfFacets");
    return m_boundaryHf;
}
const std::vector<int32_t>& TetMesh::boundaryVertexMap() const {
    requireAtLeast(3, "boundaryVertexMap");
    return m_boundaryVerts;
}

QualityReport TetMesh::quality(const QualityRules& rules) const {
    QualityReport r;
    r.minVolume = std::numeric_limits<double>::infinity();
    r.maxVolume = -r.minVolume;
    r.minDihedralDeg = 180.0;
    r.maxDihedralDeg = 0.0;
    r.minMeanRatio = 1.0;
    double sumRatio = 0;
    for (int32_t t = 0; t < static_cast<int32_t>(m_tets.size()); ++t) {
        const Tet& e = m_tets[t];
        const Vec3 p[4] = {m_positions[e[0]], m_positions[e[1]], m_positions[e[2]], m_positions[e[3]]};
        const double vol = tetVolume(p[0], p[1], p[2], p[3]);
        r.minVolume = std::min(r.minVolume, vol);
        r.maxVolume = std::max(r.maxVolume, vol);
        r.totalVolume += vol;
        double sumSq = 0;
        for (const auto& k : kEdge)
            sumSq += (p[k[0]] - p[k[1]]).squaredNorm();
        const double meanEdge = std::sqrt(sumSq / 6.0);
        const double ratio = sumSq > 0 ? 12.0 * std::cbrt(9.0 * vol * vol) / sumSq : 0.0;
        r.minMeanRatio = std::min(r.minMeanRatio, ratio);
        sumRatio += ratio;
        // Dihedral angle at each edge: pi minus the angle between the outward face normals.
        Vec3 n[4];
        bool zeroArea = false;
        for (int i = 0; i < 4; ++i) {
            const int* l = kFace[i];
            n[i] = (p[l[1]] - p[l[0]]).cross(p[l[2]] - p[l[0]]);
            const double len = n[i].norm();
            zeroArea |= len == 0;
            if (len > 0) n[i] /= len;
        }
        double minDih = 180.0;
        if (!zeroArea) {
            for (int k = 0; k < 6; ++k) {
                const double c = std::clamp(n[kEdgeFaces[k][0]].dot(n[kEdgeFaces[k][1]]), -1.0, 1.0);
                const double dih = 180.0 - std::acos(c) * 180.0 / std::numbers::pi;
                minDih = std::min(minDih, dih);
                r.maxDihedralDeg = std::max(r.maxDihedralDeg, dih);
            }
        } else {
            minDih = 0;
        }
        r.minDihedralDeg = std::min(r.minDihedralDeg, minDih);
        const bool degenerate = std::abs(vol) <= rules.degenerateRelVolume * meanEdge * meanEdge * meanEdge;
        if (degenerate)
            r.degenerate.push_back(t);
        else if (vol < 0)
            r.inverted.push_back(t);
        else if (minDih < rules.sliverAngleDeg)
            r.slivers.push_back(t);
    }
    r.meanMeanRatio = sumRatio / static_cast<double>(m_tets.size());
    return r;
}

size_t TetMesh::adjacencyBytes() const {
    return m_opp.capacity() * sizeof(int32_t) + m_facetHf.capacity() * sizeof(int32_t) +
           m_hfFacet.capacity() * sizeof(int32_t) + m_edgeHe.capacity() * sizeof(HalfEdge) +
           m_edgeVerts.capacity() * sizeof(std::array<int32_t, 2>) + m_vertEdgeStart.capacity() * sizeof(int32_t) +
           m_vertHf.capacity() * sizeof(int32_t) + m_boundaryHf.capacity() * sizeof(int32_t) +
           m_boundaryVerts.capacity() * sizeof(int32_t);
}

} // namespace viscera::sim
