#pragma once
/// Voxel remesh [A §3.2]: anatomy modelled for rendering (open, self-intersecting, overlapping
/// parts) made into one closed, manifold, self-intersection-free surface that the tetrahedralizer
/// accepts.
///
///   1. a narrow-band signed distance field per part (OpenVDB meshToLevelSet) at one voxel size;
///      a part whose holes are at most three voxels across is usually closed over by the sign flood
///      (checked: its level set must hold half its enclosed volume); an open part with wider
///      holes, or one that leaked, has no inside, so it is thickened instead: its unsigned distance
///      field is meshed at 0.75 voxels and that closed shell (1.5 voxels thick) is converted
///      (a shell that closes over its holes encloses its cavity as well);
///   2. the parts combined in order with union / difference / intersection (OpenVDB CSG);
///   3. optional smoothing of the combined level set (mean-curvature flow, a pass per iteration);
///   4. the zero isosurface (OpenVDB volumeToMesh, quads split along their shorter diagonal);
///   5. isotropic remeshing to a target edge length (CGAL Polygon_mesh_processing), edges whose
///      dihedral angle exceeds the feature angle held as constraints (hard edges stay);
///   6. checks and figures: closed, manifold, self-intersecting triangle pairs (CGAL), the
///      distance from the result to the source surfaces (mean and max, sampled at the result's
///      vertices and face centroids), the enclosed volume of source, isosurface and result.
///
/// The work runs on the calling thread (OpenVDB's parallel loops use TBB's threads). Caps refuse
/// a grid or a result that would not fit: the voxel count along the longest axis and the
/// triangles of the result.
#include "sim/mesh/tri_mesh.hpp"

#include <array>
#include <atomic>
#include <chrono>
#include <cstddef>
#include <functional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace viscera::bake {

enum class CsgOp { Union, Difference, Intersection };

/// "union", "difference", "intersection".
std::string_view csgOpName(CsgOp op);

/// The UVs of a triangle's three corners (render anatomy carries one per corner: a seam is an edge
/// whose two triangles give its ends different UVs).
using CornerUv = std::array<Eigen::Vector2d, 3>;

struct RemeshPart {
    std::string name; ///< for messages ("kidney.obj")
    sim::TriMesh surface;
    CsgOp op = CsgOp::Union;  ///< how the part combines with the parts before it (ignored for the first)
    std::vector<CornerUv> uv; ///< empty, or one per triangle of `surface`
};

/// Seam cutting [A §3.3.4] (bake/uv_transfer.hpp).
struct SeamCutParams {
    /// A crossing closer than this fraction of the edge to an end snaps that vertex onto the seam
    /// instead of splitting the edge (the split would leave a sliver), in [0, 0.45].
    double snapFraction = 0.2;
    int refineRounds = 6; ///< halvings of edges over a strip of a third chart, before the cut, in [0, 8]
};

struct SeamCutReport {
    size_t crossedEdges = 0;     ///< target edges between two charts (split at their border)
    size_t snappedVertices = 0;  ///< vertices moved onto the seam instead of a split
    size_t refinedEdges = 0;     ///< edges over a strip of a third chart, halved before the cut
    size_t splitTriangles = 0;   ///< triangles replaced by their pieces
    size_t seamEdges = 0;        ///< edges of the cut mesh lying on a seam (held hard)
    size_t unresolvedPieces = 0; ///< pieces still over two charts after the refinement
    /// The cut surface was remeshed with its chart borders held; false: that remesh made
    /// triangles intersect and the cut surface is the result as it is.
    bool remeshKept = true;
    size_t recutTriangles = 0; ///< triangles of the remeshed cut split again (a border the remesh straightened)
};

struct RemeshParams {
    /// Voxel edge, m; 0: the longest axis of the parts' bounds divided by voxelCount.
    double voxelSize = 0;
    int voxelCount = 128;        ///< voxels along the longest axis when voxelSize is 0, in [8, maxVoxelsPerAxis]
    double bandVoxels = 3;       ///< narrow band half width, voxels, in [3, 16]
    int smoothingIterations = 0; ///< mean-curvature passes on the combined level set, in [0, 100]
    /// Target edge length of the result, m; 0: 1.5 voxels. Not below half a voxel.
    double targetEdgeLength = 0;
    int remeshIterations = 3; ///< CGAL isotropic remeshing iterations, in [0, 20] (0: the isosurface)
    /// Open parts whose openings are all at most this wide (m, a hole's bounding-box diagonal) are
    /// capped (CGAL hole triangulation) and taken as closed, so that an open tube (a duct) becomes
    /// a solid one instead of a hollow shell 1.5 voxels thick; 0: none, in [0, 1].
    double fillOpenings = 0;
    double featureAngleDeg = 60;     ///< dihedral angle that makes an edge hard, degrees, in (0, 180]
    int maxVoxelsPerAxis = 2048;     ///< refuses finer grids
    size_t maxTriangles = 2'000'000; ///< refuses larger results (isosurface or remeshed)
    /// When every part has UVs: cut the remeshed surface along the parts' seams, remesh it again
    /// with the seam edges hard and transfer the UVs by seam cutting (RemeshResult::uv).
    bool transferUv = true;
    SeamCutParams seamCut;
};

struct RemeshReport {
    double voxelSize = 0;        ///< m, as used
    double targetEdgeLength = 0; ///< m, as used
    std::array<int, 3> voxels{}; ///< grid extent of the parts' bounds, voxels per axis
    size_t activeVoxels = 0;     ///< narrow-band voxels of the combined level set
    size_t openParts = 0;        ///< parts meshed through the unsigned-distance fallback
    size_t closedHoles = 0;      ///< parts with holes narrower than the band, closed over them
    size_t leakedParts = 0;      ///< parts with small holes whose inside leaked out, thickened instead
    size_t filledParts = 0;      ///< open parts capped under RemeshParams::fillOpenings, taken as closed
    size_t isoTriangles = 0;     ///< triangles of the isosurface
    size_t featureEdges = 0;     ///< edges held as hard edges while remeshing
    size_t vertices = 0, triangles = 0;
    bool closed = false;                          ///< every edge in exactly two triangles, consistently oriented
    bool manifold = false;                        ///< every vertex a single fan
    size_t selfIntersections = 0;                 ///< intersecting triangle pairs (CGAL)
    double distanceMeanMm = 0, distanceMaxMm = 0; ///< result → source surfaces, mm
    double sourceVolume = 0; ///< m³, Σ |enclosed volume| of the parts with an inside (closed, or holes under the band;
                             ///< overlaps counted twice, a self-intersecting part's folds subtracted)
    double isoVolume = 0;           ///< m³, enclosed by the isosurface
    double volume = 0;              ///< m³, enclosed by the result
    double volumeChangeFromIso = 0; ///< (volume − isoVolume) / isoVolume: what remeshing changed
    double levelSetSeconds = 0, isosurfaceSeconds = 0, remeshSeconds = 0, checkSeconds = 0;
    bool uvTransferred = false; ///< the parts had UVs and transferUv was set
    SeamCutReport seamCut;      ///< the cut before the second remesh
    size_t seamEdges = 0;       ///< hard seam edges of the result
    double uvSeconds = 0;       ///< cut, second remesh and transfer
};

struct RemeshResult {
    sim::TriMesh mesh;
    RemeshReport report;
    std::vector<CornerUv> uv;                      ///< one per triangle when report.uvTransferred
    std::vector<std::array<int32_t, 2>> seamEdges; ///< the result's edges on the source's seams
    /// When report.uvTransferred: the remeshed surface before the cut (what the closest-point and
    /// island-labelled transfers work on, for comparison).
    sim::TriMesh uncut;
};

/// Progress: called on the calling thread at each stage with its name ("level set 2/3: ureter.obj", "union",
/// "smoothing", "isosurface", "remeshing", "checks") and the estimated overall fraction in [0, 1].
/// Returning false cancels: the call throws RemeshCancelled at the next check. `cancel`, when
/// given, is also polled inside OpenVDB's parallel loops (set it from another thread to stop a
/// long level-set conversion within a fraction of a second).
using RemeshProgress = std::function<bool(std::string_view stage, double fraction)>;

struct RemeshCancelled : std::runtime_error {
    RemeshCancelled() : std::runtime_error("remesh cancelled") {}
};

/// Throws std::invalid_argument naming the field when a parameter is out of range, InputError
/// naming the part when a part is empty or not finite, or naming the cap when the grid or the
/// result exceeds it ("voxel size 0.1 mm gives 4000 voxels along the longest axis (cap
/// RemeshParams::maxVoxelsPerAxis = 2048)"), and when the result is not closed, not manifold or
/// self-intersects (with the count).
RemeshResult voxelRemesh(const std::vector<RemeshPart>& parts, const RemeshParams& params,
                         const RemeshProgress& progress = {}, const std::atomic<bool>* cancel = nullptr);

/// Writes a surface as Wavefront OBJ (vertices in metres, faces 1-based), atomically.
void writeObj(const std::string& path, const sim::TriMesh& mesh);

namespace detail {

/// Stage 1–4 (OpenVDB, remesh_vdb.cpp): the isosurface of the combined level set. Fills
/// voxelSize, voxels, activeVoxels, openParts, closedHoles, isoTriangles, levelSetSeconds, isosurfaceSeconds.
/// Reports a stage to `progress`; throws RemeshCancelled when it returns false or *cancel is set.
void reportStage(const RemeshProgress& progress, const std::atomic<bool>* cancel, const std::string& stage,
                 double fraction);
/// Throws RemeshCancelled when *cancel is set (between OpenVDB calls).
void checkCancel(const std::atomic<bool>* cancel);
/// Seconds since t0 (steady clock).
double secondsSince(std::chrono::steady_clock::time_point t0);

/// The largest extent (bounding-box diagonal, m) of a hole of `mesh`: a loop of edges that belong
/// to one triangle only; 0 when there is none. O(triangles).
double largestHoleDiameter(const sim::TriMesh& mesh);

/// `mesh` with every hole capped by CGAL's hole triangulation (remesh.cpp); throws InputError
/// naming `name` when a hole cannot be capped.
sim::TriMesh capOpenings(const sim::TriMesh& mesh, const std::string& name);

/// Throws RemeshCancelled when progress returns false or *cancel becomes true.
sim::TriMesh combinedIsosurface(const std::vector<RemeshPart>& parts, const RemeshParams& params,
                                const RemeshProgress& progress, const std::atomic<bool>* cancel, RemeshReport& report);

} // namespace detail

} // namespace viscera::bake
