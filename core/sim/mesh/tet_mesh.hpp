#pragma once
/// Tetrahedral mesh with the compact half-face (CHF) adjacency of [B §2.1.2–2.1.3].
///
/// Level 0: geometry G (#V × 3, metres) and topology T (#T × 4 vertex indices, positive volume
///          for a well-formed element).
/// Level 1: opposite half-facets O (4·#T); O[f] = kNone (⊥) on the boundary.
/// Level 2: explicit facets F (one half-facet each), edges E (one half-edge each, a boundary
///          half-edge for a boundary edge) and vertex → half-facet I (a boundary half-facet for a
///          boundary vertex).
/// Level 3: the boundary as a TriMesh with maps to half-facets and mesh vertices.
///
/// Indexing: half-vertex and half-facet 4t+i name the i-th vertex of tet t and the facet opposite
/// it (Table 2.1). A half-edge is a pair (f, v): the half-facet f it lies in and the half-vertex v
/// it starts at (equivalently the half-facet opposite its start vertex, as in Table 2.2).
/// Levels are built lazily and explicitly: requireLevel(k). A query of a level not yet built throws
/// std::logic_error naming the query and the call to make.
#include "sim/mesh/tri_mesh.hpp"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace viscera::sim {

using Tet = std::array<int32_t, 4>;
inline constexpr int32_t kNone = -1; ///< the bottom element ⊥

struct HalfEdge {
    int32_t f = kNone; ///< half-facet containing the edge
    int32_t v = kNone; ///< half-vertex (same cell) at which the half-edge starts
    bool valid() const { return f != kNone; }
    friend bool operator==(const HalfEdge&, const HalfEdge&) = default;
};

/// Per-element quality figures and the elements that fail the rules.
struct QualityReport {
    std::vector<int32_t> inverted;                        ///< signed volume < 0
    std::vector<int32_t> degenerate;                      ///< |volume| <= degenerateRelVolume · (mean edge)^3
    std::vector<int32_t> slivers;                         ///< not degenerate, min dihedral angle < sliverAngleDeg
    double minVolume = 0, maxVolume = 0, totalVolume = 0; ///< m^3, signed
    double minDihedralDeg = 0, maxDihedralDeg = 0;
    double minMeanRatio = 0, meanMeanRatio = 0; ///< mean-ratio quality in (0, 1], 1 = regular
    bool ok() const { return inverted.empty() && degenerate.empty() && slivers.empty(); }
};

struct QualityRules {
    double degenerateRelVolume = 1e-12;
    double sliverAngleDeg = 5.0;
};

class TetMesh {
public:
    /// Validates level 0 and returns a mesh with level 1 built. Throws std::invalid_argument
    /// ("<origin>: tet 12 references vertex 99 (mesh has 50 vertices)") when: there are no tets,
    /// a coordinate is not finite, an index is out of range, a tet repeats a vertex, or a facet is
    /// shared by more than two tets (non-manifold). Inverted elements are accepted and reported by
    /// quality().
    static std::unique_ptr<TetMesh> fromArrays(std::vector<Vec3> positions, std::vector<Tet> tets,
                                               const std::string& origin = "sim::TetMesh::fromArrays()");

    TetMesh(const TetMesh&) = delete;
    TetMesh& operator=(const TetMesh&) = delete;
    std::unique_ptr<TetMesh> clone() const;

    // ---- level 0 ------------------------------------------------------------------------
    size_t vertexCount() const { return m_positions.size(); }
    size_t tetCount() const { return m_tets.size(); }
    const std::vector<Vec3>& positions() const { return m_positions; }
    /// Mutable geometry (topology is fixed after construction).
    std::vector<Vec3>& positions() { return m_positions; }
    const std::vector<Tet>& tets() const { return m_tets; }
    /// r30: vertex of half-vertex h = 4t+i.
    int32_t vertex(int32_t h) const { return m_tets[h >> 2][h & 3]; }
    /// The three vertices of half-facet f in outward counter-clockwise order (Table 2.1).
    std::array<int32_t, 3> halfFacetVertices(int32_t f) const;
    double signedVolume(int32_t t) const;
    /// Barycentric coordinates of p with respect to tet t [B eq. 2.3] (sum to 1).
    Eigen::Vector4d barycentric(int32_t t, const Vec3& p) const;

    // ---- half-facet navigation (any level) [B eq. 2.9–2.11] ------------------------------
    static int32_t cellOf(int32_t f) { return f >> 2; }
    static int32_t nxt(int32_t f) { return 4 * (f >> 2) + ((f + 1) & 3); }
    static int32_t mid(int32_t f) { return 4 * (f >> 2) + ((f + 2) & 3); }
    static int32_t prv(int32_t f) { return 4 * (f >> 2) + ((f + 3) & 3); }

    // ---- half-edge navigation [B eq. 2.13–2.16] -------------------------------------------
    static HalfEdge heNext(HalfEdge e);
    static HalfEdge hePrev(HalfEdge e);
    static HalfEdge heMate(HalfEdge e);
    /// Radial half-edge in the cell across e.f, or {kNone, kNone} on the boundary. Level 1.
    HalfEdge heRadial(HalfEdge e) const;
    /// {start vertex, end vertex} of a half-edge.
    std::array<int32_t, 2> halfEdgeVertices(HalfEdge e) const;

    // ---- level 1 ---------------------------------------------------------------------------
    /// opp[f] [B eq. 2.12]; kNone for a boundary half-facet.
    int32_t opp(int32_t f) const;
    bool isBoundaryHalfFacet(int32_t f) const { return opp(f) == kNone; }
    /// r33: cells adjacent to t across its facets (kNone on the boundary), in facet order.
    std::array<int32_t, 4> adjacentCells(int32_t t) const;

    // ---- level 2 ---------------------------------------------------------------------------
    void requireLevel(int level);
    int level() const { return m_level; }
    size_t facetCount() const;
    size_t edgeCount() const;
    /// F: a half-facet of facet i; facetOfHalfFacet: the inverse map.
    int32_t facetHalfFacet(int32_t i) const;
    int32_t facetOfHalfFacet(int32_t f) const;
    /// E: a half-edge of edge i (a boundary half-edge when the edge is on the boundary).
    HalfEdge edgeHalfEdge(int32_t i) const;
    /// The edge (a < b) as sorted vertex pair, and the lookup by vertices (kNone if absent).
    std::array<int32_t, 2> edgeVertices(int32_t i) const;
    int32_t findEdge(int32_t a, int32_t b) const;
    /// I: a half-facet incident to vertex v (a boundary one for a boundary vertex), kNone if v
    /// belongs to no tet.
    int32_t vertexHalfFacet(int32_t v) const;
    bool isBoundaryVertex(int32_t v) const;
    bool isBoundaryEdge(int32_t i) const;

    // ---- queries [B Alg. 2.1–2.5] (level 2); allocation-free Into forms clear `out` first ----
    /// r03: cells incident to v.
    void cellsOfVertexInto(int32_t v, std::vector<int32_t>& out) const;
    /// r02 (Alg. 2.1): all half-facets of the cells incident to v.
    void starFacetsOfVertexInto(int32_t v, std::vector<int32_t>& out) const;
    /// r02 open (Alg. 2.2): half-facets of incident cells that contain v.
    void openStarFacetsOfVertexInto(int32_t v, std::vector<int32_t>& out) const;
    /// r02 link (Alg. 2.3): half-facets of incident cells opposite v.
    void linkFacetsOfVertexInto(int32_t v, std::vector<int32_t>& out) const;
    /// r12 open (Alg. 2.4): half-facets containing the edge of half-edge e.
    void openStarFacetsOfEdgeInto(HalfEdge e, std::vector<int32_t>& out) const;
    /// r12 link (Alg. 2.5): in every cell around the edge, the two half-facets opposite its ends.
    void linkFacetsOfEdgeInto(HalfEdge e, std::vector<int32_t>& out) const;
    /// Cells around the edge of half-edge e.
    void cellsOfEdgeInto(HalfEdge e, std::vector<int32_t>& out) const;

    // ---- level 3 ---------------------------------------------------------------------------
    /// Boundary surface (outward oriented), its triangle → half-facet map and its vertex → mesh
    /// vertex map.
    const TriMesh& boundary() const;
    const std::vector<int32_t>& boundaryHalfFacets() const;
    const std::vector<int32_t>& boundaryVertexMap() const;

    // ---- quality ---------------------------------------------------------------------------
    QualityReport quality(const QualityRules& rules = {}) const;
    /// Bytes held by the adjacency containers of all built levels.
    size_t adjacencyBytes() const;

private:
    TetMesh() = default;
    void requireAtLeast(int level, const char* query) const;
    void buildLevel1(const std::string& origin);
    void buildLevel2();
    void buildLevel3();

    std::vector<Vec3> m_positions;
    std::vector<Tet> m_tets;
    int m_level = 0;
    // level 1
    std::vector<int32_t> m_opp;
    // level 2
    std::vector<int32_t> m_facetHf; // F
    std::vector<int32_t> m_hfFacet; // half-facet -> facet
    std::vector<HalfEdge> m_edgeHe; // E
    std::vector<std::array<int32_t, 2>> m_edgeVerts;
    std::vector<int32_t> m_vertEdgeStart; // CSR by smaller vertex into m_edgeVerts (sorted)
    std::vector<int32_t> m_vertHf;        // I
    // level 3
    TriMesh m_boundary;
    std::vector<int32_t> m_boundaryHf;
    std::vector<int32_t> m_boundaryVerts;
};

} // namespace viscera::sim
