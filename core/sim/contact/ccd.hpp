#pragma once
/// Continuous collision detection between boundary surfaces of a TetMesh [B §2.2.6]: vertex–face and
/// edge–edge events with their times, for nodes moving linearly from x0 to x1 during a step. A
/// bounding-volume hierarchy over the boundary triangles and edges (topology built once, boxes
/// refitted to the swept primitives every call) prunes the pairs; each candidate solves the cubic
/// coplanarity equation and checks proximity at its roots. Pairs that share a vertex are skipped.
#include "sim/mesh/tet_mesh.hpp"

#include <Eigen/Geometry>

#include <vector>

namespace viscera::sim {

enum class CollisionKind { VertexFace, EdgeEdge };

struct Collision {
    CollisionKind kind = CollisionKind::VertexFace;
    double t = 0; ///< time of contact in [0, 1] (fraction of the step)
    /// VertexFace: {vertex, face0, face1, face2}; EdgeEdge: {a0, a1, b0, b1} (mesh vertex ids).
    std::array<int32_t, 4> v{};
    /// VertexFace: barycentric coordinates of the contact point on the face; EdgeEdge: (α, β, 0) with
    /// the points (1−α) a0 + α a1 and (1−β) b0 + β b1.
    Vec3 w = Vec3::Zero();
    /// Unit normal at contact, pointing from the face (edge b) to the side the vertex (edge a) came from.
    Vec3 normal = Vec3::UnitZ();
};

class ContactDetector {
public:
    /// Throws std::logic_error when the mesh lacks adjacency level 3. Without `selfContact`, pairs
    /// whose primitives belong to the same body (connected component of the tets) are skipped:
    /// only contact between bodies is detected (the closing boundaries of a suture).
    explicit ContactDetector(const TetMesh& mesh, bool selfContact = false);

    /// Appends the collisions between x0 and x1, sorted by time. `thickness` (m) is the proximity at
    /// which a coplanarity root counts as contact. Never throws.
    void detect(const std::vector<Vec3>& x0, const std::vector<Vec3>& x1, double thickness,
                std::vector<Collision>& out);

    size_t triangleCount() const { return m_tris.size(); }
    size_t edgeCount() const { return m_edges.size(); }
    /// Candidate pairs tested in the last detect() (for reports and benchmarks).
    size_t lastCandidates() const { return m_candidates; }

private:
    struct Node {
        Eigen::AlignedBox3d box;
        int left = -1, right = -1; // children, −1 for a leaf
        int first = 0, count = 0;  // leaf range in the primitive order
    };
    struct Tree {
        std::vector<Node> nodes;
        std::vector<int> order; // primitive ids
    };
    static void build(Tree& tree, const std::vector<Vec3>& centroids, std::vector<int> ids);
    template <class BoxOf> static void refit(Tree& tree, BoxOf&& boxOf);

    std::vector<std::array<int32_t, 3>> m_tris;  // mesh vertex ids
    std::vector<std::array<int32_t, 2>> m_edges; // mesh vertex ids
    std::vector<int32_t> m_verts;                // boundary vertices (mesh ids)
    std::vector<int32_t> m_body;                 // body index (connected component) per mesh vertex
    bool m_selfContact = false;
    std::vector<Tree> m_triTrees, m_edgeTrees; // per body (one tree with selfContact)
    size_t m_candidates = 0;
};

/// First time t in [0, 1] at which the moving point p comes within `thickness` of the moving
/// triangle (a, b, c) on a coplanarity root; false when none. w receives the barycentric point.
bool vertexFaceCcd(const std::array<Vec3, 4>& x0, const std::array<Vec3, 4>& x1, double thickness, double& t, Vec3& w);
/// Same for the moving edges (a0, a1) and (b0, b1); w = (α, β, 0).
bool edgeEdgeCcd(const std::array<Vec3, 4>& x0, const std::array<Vec3, 4>& x1, double thickness, double& t, Vec3& w);

} // namespace viscera::sim
