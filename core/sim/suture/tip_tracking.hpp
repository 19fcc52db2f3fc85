#pragma once
/// Tip tracking through a tetrahedral mesh [B §3.2.1, Alg. 3.1–3.2, §3.2.2.1]: a point sliding along
/// a NeedleCurve from α = a to α = b is followed from cell to cell; the outside of the mesh is the
/// single cell ⊥ (kNone) incident to every boundary facet. Exits through a face go to the opposite
/// half-facet's cell; exits through an edge or a vertex (Fig. 3.5) take the next cell among those
/// of the edge's or vertex's face link (linkFacetsOfEdgeInto / linkFacetsOfVertexInto), so the
/// visited cells stay a chain that intersects consecutively.
///
/// Positions are passed explicitly (the deformed state of the simulation); the topology comes from
/// the mesh, which must have adjacency level 3 (boundary). Cost: per crossing, four plane tests
/// (arc: a cos θ + b sin θ = c, [B eq. 3.21–3.25]); from ⊥ one test per boundary facet.
#include "sim/mesh/tet_mesh.hpp"
#include "sim/suture/needle_curve.hpp"

#include <vector>

namespace viscera::sim {

enum class CrossingKind { Face, Edge, Vertex };

struct Crossing {
    double alpha = 0;         ///< curve parameter of the crossing point, m
    int32_t fromCell = kNone; ///< cell left (kNone = ⊥)
    int32_t toCell = kNone;   ///< cell entered (kNone = ⊥)
    /// A half-facet carrying the crossing point: a facet of toCell, or the boundary half-facet of
    /// fromCell when toCell is ⊥.
    int32_t face = kNone;
    Vec3 xi = Vec3::Zero(); ///< barycentric coordinates of the point on `face` (its vertex order)
    CrossingKind kind = CrossingKind::Face;
    bool boundary() const { return fromCell == kNone || toCell == kNone; }
};

struct TrackOptions {
    /// Stop right after the first crossing into or out of the mesh (boundary puncture handling).
    bool stopAtBoundary = false;
    int maxCrossings = 100000; ///< guard; the walk ends there
};

class TipTracker {
public:
    /// Throws std::logic_error when the mesh lacks adjacency level 3.
    explicit TipTracker(const TetMesh& mesh);

    /// Follows the curve over (a, b] starting in `cell` (kNone = ⊥), appends the crossings to `out`
    /// in parameter order and returns the cell reached (where the walk stopped with stopAtBoundary;
    /// `stoppedAt` then receives the parameter). Never throws.
    int32_t track(const std::vector<Vec3>& x, const NeedleCurve& curve, double a, double b, int32_t cell,
                  std::vector<Crossing>& out, const TrackOptions& options = {}, double* stoppedAt = nullptr) const;

    /// Cell containing p (kNone when outside), by scanning all cells.
    int32_t locate(const std::vector<Vec3>& x, const Vec3& p) const;
    /// Barycentric coordinates of p in tet t at positions x.
    Eigen::Vector4d barycentric(const std::vector<Vec3>& x, int32_t t, const Vec3& p) const;
    const TetMesh& mesh() const { return m_mesh; }
    double lengthScale() const { return m_h; }

private:
    struct Exit {
        double alpha = 0;
        int face = -1; // local face index 0..3
        bool found = false;
    };
    Exit exitOf(const std::vector<Vec3>& x, const NeedleCurve& c, int32_t t, double s, double b) const;
    int32_t chooseNext(const std::vector<Vec3>& x, const NeedleCurve& c, const std::vector<int32_t>& cands,
                       int32_t from, double s, double b) const;
    void faceBary(const std::vector<Vec3>& x, int32_t f, const Vec3& p, Vec3& xi) const;

    const TetMesh& m_mesh;
    double m_h = 1;       // mean edge length
    double m_epsS = 0;    // parameter tolerance
    double m_epsB = 1e-9; // barycentric tolerance
};

} // namespace viscera::sim
