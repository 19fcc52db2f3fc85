#pragma once
/// Curve skeleton of a body and the skeleton → mesh-node correspondence used by skeleton-based
/// stiffness painting [A §4.3.5].
///
/// The skeleton itself is extracted at authoring time (bake::extractSkeleton(), mean curvature
/// flow [TAOZ12]); this header holds only the plain result so that the player and the core never
/// need CGAL. Units: metres, world frame (the frame of the mesh it was extracted from).
#include "sim/mesh/tet_mesh.hpp"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace viscera::sim {

/// A curve skeleton: nodes p_j (#m, metres), undirected edges and, for every vertex of the mesh
/// it was extracted from, the node that vertex contracted to (its surface correspondence).
struct Skeleton {
    std::vector<Vec3> nodes;                   ///< p_j, #m, metres
    std::vector<std::array<int32_t, 2>> edges; ///< node pairs (a < b), unique, no self loop
    /// One entry per vertex of the mesh the skeleton was extracted from (a TriMesh, or a TetMesh
    /// whose interior vertices are kNone): the node the vertex contracted to, or kNone for a
    /// vertex that is not on the skeletonized surface.
    std::vector<int32_t> vertexNode;

    size_t nodeCount() const { return nodes.size(); }
    /// Number of edges incident to each node.
    std::vector<int32_t> degrees() const;
    /// Connected components of the node graph (component index per node; returns the count).
    int32_t components(std::vector<int32_t>& componentOfNode) const;
    /// Independent cycles of the graph: #edges − #nodes + #components (0 for a tree; 1 for a
    /// single loop, e.g. the skeleton of a torus).
    int64_t cycleRank() const;
};

/// Checks a skeleton against the mesh it is applied to. Throws std::invalid_argument
/// ("<origin>: skeleton node 3 has a non-finite coordinate") when: there are no nodes, a node
/// coordinate is not finite, an edge index is out of range, an edge is a self loop or repeated,
/// vertexNode does not have `vertexCount` entries, an entry is neither kNone nor a node index,
/// or no vertex corresponds to any node.
void validateSkeleton(const Skeleton& skeleton, size_t vertexCount, const std::string& origin);

/// Correspondence Π_j between skeleton nodes and ALL mesh nodes (interior ones included),
/// built as [A §4.3.5] describes:
///   1. Π_j starts as the surface correspondence of p_j (Skeleton::vertexNode);
///   2. r_j = max_{i ∈ Π_j} |x_i − p_j| (0 when Π_j is empty);
///   3. every mesh node i with |x_i − p_j| <= r_j joins Π_j.
/// Coverage guarantee (our addition; the thesis assumes step 3 reaches every node): a node that
/// no ball (p_j, r_j) reaches is a *fallback* node. It is projected on the skeleton (closest
/// point over all edges as segments and all isolated nodes) and joins Π_j of the end of the
/// closest segment nearer to the projection (ties: the lower node index). Every node therefore
/// belongs to at least one Π_j.
struct SkeletonNodeMap {
    std::vector<double> radius;         ///< r_j, metres, #m
    std::vector<int32_t> start;         ///< CSR: Π_j = members[start[j], start[j+1]), #m + 1
    std::vector<int32_t> members;       ///< mesh node indices, ascending within each Π_j
    std::vector<int32_t> fallbackNodes; ///< nodes mapped by the fallback, ascending
    std::vector<int32_t> fallbackNode;  ///< the node each fallback node was given (same order)
    size_t meshNodeCount = 0;

    size_t skeletonNodeCount() const { return radius.size(); }
    /// Number of mesh nodes that belong to at least one Π_j (== meshNodeCount by construction).
    size_t coveredCount() const;
};

/// Builds Π_j for mesh nodes at `positions` (#n, metres). `skeleton.vertexNode` must have one
/// entry per position (validateSkeleton() is called with `origin`). Cost O(n·m) distance tests
/// for step 3 plus O(f·(m + #edges)) for the f fallback nodes.
SkeletonNodeMap mapNodesToSkeleton(const std::vector<Vec3>& positions, const Skeleton& skeleton,
                                   const std::string& origin = "sim::mapNodesToSkeleton()");

/// As above for the nodes of a tet mesh.
inline SkeletonNodeMap mapNodesToSkeleton(const TetMesh& mesh, const Skeleton& skeleton,
                                          const std::string& origin = "sim::mapNodesToSkeleton()") {
    return mapNodesToSkeleton(mesh.positions(), skeleton, origin);
}

} // namespace viscera::sim
