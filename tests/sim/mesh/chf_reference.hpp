#pragma once
// Brute-force adjacency used as the reference for the CHF queries: every answer is recomputed by
// scanning all tets, independently of the half-face containers.
#include "sim/mesh/tet_mesh.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>
#include <set>
#include <vector>

namespace viscera::sim::testing {

inline std::vector<int32_t> sorted(std::vector<int32_t> v) {
    std::sort(v.begin(), v.end());
    return v;
}

inline bool tetHas(const Tet& t, int32_t v) {
    return std::find(t.begin(), t.end(), v) != t.end();
}

/// Checks every CHF level against brute force. `samples` bounds the number of vertices and edges
/// checked on large meshes (all of them on small ones).
inline void expectChfMatchesBruteForce(TetMesh& m, size_t samples, uint32_t seed) {
    m.requireLevel(3);
    const auto& tets = m.tets();
    const auto nt = static_cast<int32_t>(tets.size());

    // Level 1: opposite half-facets from a map of sorted vertex triples.
    std::map<std::array<int32_t, 3>, std::vector<int32_t>> byFacet;
    for (int32_t f = 0; f < 4 * nt; ++f) {
        auto v = m.halfFacetVertices(f);
        std::sort(v.begin(), v.end());
        byFacet[v].push_back(f);
    }
    size_t boundaryCount = 0;
    for (const auto& [key, hfs] : byFacet) {
        ASSERT_LE(hfs.size(), 2u);
        if (hfs.size() == 1) {
            EXPECT_EQ(m.opp(hfs[0]), kNone);
            ++boundaryCount;
        } else {
            EXPECT_EQ(m.opp(hfs[0]), hfs[1]);
            EXPECT_EQ(m.opp(hfs[1]), hfs[0]);
        }
    }
    EXPECT_EQ(m.facetCount(), byFacet.size());
    EXPECT_EQ(m.boundaryHalfFacets().size(), boundaryCount);
    for (int32_t f = 0; f < 4 * nt; ++f) {
        const int32_t id = m.facetOfHalfFacet(f);
        ASSERT_NE(id, kNone);
        const int32_t rep = m.facetHalfFacet(id);
        EXPECT_TRUE(rep == f || rep == m.opp(f));
    }
    for (int32_t t = 0; t < nt; ++t) {
        auto adj = m.adjacentCells(t);
        for (int i = 0; i < 4; ++i) {
            // Reference: the tet sharing the facet opposite local vertex i.
            auto v = m.halfFacetVertices(4 * t + i);
            std::sort(v.begin(), v.end());
            int32_t expect = kNone;
            for (int32_t g : byFacet[v])
                if (TetMesh::cellOf(g) != t) expect = TetMesh::cellOf(g);
            EXPECT_EQ(adj[i], expect);
        }
    }

    // Level 2: edges.
    std::set<std::array<int32_t, 2>> edges;
    for (const Tet& t : tets)
        for (int a = 0; a < 4; ++a)
            for (int b = a + 1; b < 4; ++b)
                edges.insert({std::min(t[a], t[b]), std::max(t[a], t[b])});
    ASSERT_EQ(m.edgeCount(), edges.size());
    for (int32_t i = 0; i < static_cast<int32_t>(m.edgeCount()); ++i) {
        auto ev = m.edgeVertices(i);
        EXPECT_EQ(m.findEdge(ev[1], ev[0]), i);
        auto hv = m.halfEdgeVertices(m.edgeHalfEdge(i));
        EXPECT_EQ(std::min(hv[0], hv[1]), ev[0]);
        EXPECT_EQ(std::max(hv[0], hv[1]), ev[1]);
    }
    // Euler characteristic of a tetrahedralized ball.
    const auto usedVerts = [&] {
        std::set<int32_t> s;
        for (const Tet& t : tets)
            s.insert(t.begin(), t.end());
        return static_cast<int64_t>(s.size());
    }();
    EXPECT_EQ(usedVerts - static_cast<int64_t>(m.edgeCount()) + static_cast<int64_t>(m.facetCount()) - nt, 1);

    // Half-edge navigation on every half-edge of every cell.
    for (int32_t f = 0; f < 4 * nt; ++f) {
        const int32_t base = f & ~3;
        for (int i = 0; i < 4; ++i) {
            if (base + i == f) continue;
            const HalfEdge e{f, base + i};
            const auto ev = m.halfEdgeVertices(e);
            const HalfEdge n = TetMesh::heNext(e);
            EXPECT_EQ(m.halfEdgeVertices(n)[0], ev[1]);
            EXPECT_EQ(TetMesh::heNext(TetMesh::heNext(n)), e);
            EXPECT_EQ(TetMesh::hePrev(n), e);
            const HalfEdge mt = TetMesh::heMate(e);
            EXPECT_NE(mt.f, e.f);
            EXPECT_EQ(TetMesh::cellOf(mt.f), TetMesh::cellOf(f));
            EXPECT_EQ(m.halfEdgeVertices(mt), (std::array<int32_t, 2>{ev[1], ev[0]}));
            EXPECT_EQ(TetMesh::heMate(mt), e);
            const HalfEdge r = m.heRadial(e);
            if (m.opp(f) == kNone) {
                EXPECT_FALSE(r.valid());
            } else {
                ASSERT_TRUE(r.valid());
                EXPECT_EQ(r.f, m.opp(f));
                EXPECT_EQ(m.halfEdgeVertices(r), (std::array<int32_t, 2>{ev[1], ev[0]}));
                EXPECT_EQ(m.heRadial(r), e);
            }
        }
    }

    // Vertex queries (Alg. 2.1–2.3) on a sample of vertices.
    std::mt19937 rng(seed);
    std::vector<int32_t> verts;
    for (int32_t v = 0; v < static_cast<int32_t>(m.vertexCount()); ++v)
        verts.push_back(v);
    std::shuffle(verts.begin(), verts.end(), rng);
    if (verts.size() > samples) verts.resize(samples);
    std::vector<int32_t> out;
    for (int32_t v : verts) {
        std::vector<int32_t> cells, star, open, link;
        for (int32_t t = 0; t < nt; ++t) {
            if (!tetHas(tets[t], v)) continue;
            cells.push_back(t);
            for (int i = 0; i < 4; ++i) {
                star.push_back(4 * t + i);
                (tets[t][i] == v ? link : open).push_back(4 * t + i);
            }
        }
        m.cellsOfVertexInto(v, out);
        EXPECT_EQ(sorted(out), cells) << "vertex " << v;
        m.starFacetsOfVertexInto(v, out);
        EXPECT_EQ(sorted(out), star);
        m.openStarFacetsOfVertexInto(v, out);
        EXPECT_EQ(sorted(out), open);
        m.linkFacetsOfVertexInto(v, out);
        EXPECT_EQ(sorted(out), link);
        bool onBoundary = false;
        for (int32_t f : m.boundaryHalfFacets())
            for (int32_t w : m.halfFacetVertices(f))
                onBoundary |= w == v;
        EXPECT_EQ(m.isBoundaryVertex(v), onBoundary);
    }

    // Edge queries (Alg. 2.4–2.5) on a sample of edges, from every half-edge of the edge.
    std::vector<int32_t> edgeIds(m.edgeCount());
    for (size_t i = 0; i < edgeIds.size(); ++i)
        edgeIds[i] = static_cast<int32_t>(i);
    std::shuffle(edgeIds.begin(), edgeIds.end(), rng);
    if (edgeIds.size() > samples) edgeIds.resize(samples);
    for (int32_t id : edgeIds) {
        const auto [a, b] = m.edgeVertices(id);
        std::vector<int32_t> cells, open, link;
        for (int32_t t = 0; t < nt; ++t) {
            if (!tetHas(tets[t], a) || !tetHas(tets[t], b)) continue;
            cells.push_back(t);
            for (int i = 0; i < 4; ++i) {
                const int32_t w = tets[t][i];
                (w == a || w == b ? link : open).push_back(4 * t + i);
            }
        }
        bool boundaryEdge = false;
        for (int32_t f : m.boundaryHalfFacets()) {
            auto fv = m.halfFacetVertices(f);
            boundaryEdge |= std::count(fv.begin(), fv.end(), a) && std::count(fv.begin(), fv.end(), b);
        }
        EXPECT_EQ(m.isBoundaryEdge(id), boundaryEdge);
        // Start from every half-edge of the edge in every cell.
        for (int32_t t : cells)
            for (int i = 0; i < 4; ++i) {
                const int32_t f = 4 * t + i;
                auto fv = m.halfFacetVertices(f);
                if (!std::count(fv.begin(), fv.end(), a) || !std::count(fv.begin(), fv.end(), b)) continue;
                HalfEdge e{f, kNone};
                for (int j = 0; j < 4; ++j) {
                    if (4 * t + j == f) continue;
                    HalfEdge c{f, 4 * t + j};
                    auto cv = m.halfEdgeVertices(c);
                    if ((cv[0] == a && cv[1] == b) || (cv[0] == b && cv[1] == a)) e = c;
                }
                ASSERT_TRUE(e.v != kNone);
                m.cellsOfEdgeInto(e, out);
                EXPECT_EQ(sorted(out), cells) << "edge " << a << "-" << b;
                m.openStarFacetsOfEdgeInto(e, out);
                EXPECT_EQ(sorted(out), open);
                m.linkFacetsOfEdgeInto(e, out);
                EXPECT_EQ(sorted(out), link);
            }
    }

    // Level 3: the boundary is a closed, outward-oriented surface enclosing the mesh volume.
    const TriMesh& surf = m.boundary();
    EXPECT_TRUE(surf.isClosedOriented());
    double vol = 0;
    for (int32_t t = 0; t < nt; ++t)
        vol += m.signedVolume(t);
    EXPECT_NEAR(surf.signedVolume(), vol, 1e-9 * std::abs(vol));
}

} // namespace viscera::sim::testing
