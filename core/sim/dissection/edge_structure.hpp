#pragma once
/// Edge-based mesh structure for dissection [A §5.3.1].
///
/// The edge is the basic element: every unique edge of a triangle mesh (fascia) or a tet mesh
/// (fat) keeps the list of primitives (triangles or tets) that share it, and every primitive keeps
/// share_count[k], initially its number of edges (3 or 6). Dissecting an edge decrements the
/// share_count of every primitive around it. A primitive whose share_count differs from its
/// initial value is cut: it no longer contributes elasticity and is not rendered. No vertex is
/// created or removed and the topology is never rebuilt; cutting is O(primitives around the edge).
///
/// Edge numbering: edges sorted by (lower vertex, upper vertex), deterministic.
#include "sim/mesh/tet_mesh.hpp"
#include "sim/mesh/tri_mesh.hpp"

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace viscera::sim {

class EdgeStructure {
public:
    using Edge = std::array<int32_t, 2>;

    /// Triangles (#F × 3 vertex indices < vertexCount). Throws std::invalid_argument
    /// ("sim::EdgeStructure::fromTriangles(): triangle 3 references vertex 99 (10 vertices)") on
    /// no primitive, an index out of range or a repeated vertex.
    static EdgeStructure fromTriangles(const std::vector<Tri>& triangles, size_t vertexCount);
    /// Tets (#T × 4); same rules.
    static EdgeStructure fromTets(const std::vector<Tet>& tets, size_t vertexCount);

    size_t vertexCount() const { return m_vertexCount; }
    size_t edgeCount() const { return m_edges.size(); }
    size_t primitiveCount() const { return m_share.size(); }
    /// Edges per primitive: 3 (triangles) or 6 (tets); the initial share_count.
    int initialShareCount() const { return m_edgesPerPrim; }

    const Edge& edge(size_t e) const { return m_edges[e]; }
    /// Primitives sharing edge e (ascending).
    std::span<const int32_t> primitivesOf(size_t e) const {
        return {m_edgePrims.data() + m_edgePrimStart[e], m_edgePrims.data() + m_edgePrimStart[e + 1]};
    }
    /// Edges of primitive p (3 or 6).
    std::span<const int32_t> edgesOf(size_t p) const {
        return {m_primEdges.data() + size_t(m_edgesPerPrim) * p, size_t(m_edgesPerPrim)};
    }
    /// Edge index of (a, b) in either order, or −1. O(log degree).
    int32_t findEdge(int32_t a, int32_t b) const;

    int shareCount(size_t p) const { return m_share[p]; }
    bool isCut(size_t p) const { return m_share[p] != m_edgesPerPrim; }
    bool isDissected(size_t e) const { return m_dissected[e] != 0; }
    /// True when no primitive around e is intact (a free edge, [A §5.3.3]).
    bool isOrphaned(size_t e) const;
    size_t dissectedEdgeCount() const { return m_dissectedCount; }
    size_t cutPrimitiveCount() const { return m_cutCount; }

    /// Dissects edge e: marks it and decrements share_count of every primitive around it; the
    /// primitives that become cut by this call are appended to newlyCut (when not null). Returns
    /// false (and changes nothing) when e was already dissected. Throws std::out_of_range on a bad
    /// e.
    bool dissect(size_t e, std::vector<int32_t>* newlyCut = nullptr);
    /// Intact flags (1: share_count at its initial value) of all primitives into out.
    void intactMaskInto(std::vector<uint8_t>& out) const;
    /// Back to the initial state (nothing dissected).
    void reset();

private:
    template <size_t K>
    static EdgeStructure build(const std::vector<std::array<int32_t, K>>& prims, size_t vertexCount, const char* where,
                               const char* primName);

    size_t m_vertexCount = 0;
    int m_edgesPerPrim = 3;
    std::vector<Edge> m_edges;
    std::vector<uint32_t> m_edgePrimStart; ///< #E + 1
    std::vector<int32_t> m_edgePrims;
    std::vector<int32_t> m_primEdges;        ///< #P × edgesPerPrim
    std::vector<uint32_t> m_vertexEdgeStart; ///< #V + 1: edges (a, b) with a = min vertex
    std::vector<int> m_share;
    std::vector<uint8_t> m_dissected;
    size_t m_dissectedCount = 0, m_cutCount = 0;
};

} // namespace viscera::sim
