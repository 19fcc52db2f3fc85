#pragma once
/// Curve-skeleton extraction by mean curvature flow [A §4.3.5, after Tagliasacchi et al. 2012
/// (TAOZ12)]: the closed surface is contracted along the mean curvature flow, attracted to its
/// Voronoi poles (medially centred), remeshed by edge collapse and split, until it degenerates into
/// a curve; the collapse history gives, for every surface vertex, the skeleton node it contracted
/// to. Implemented with CGAL::Mean_curvature_flow_skeletonization (private to viscera::bake).
///
/// The surface is translated to its bounding-box centre and scaled to a unit bounding-box
/// diagonal before contraction (CGAL's degeneracy thresholds are absolute) and the nodes are
/// mapped back, so the result does not depend on the unit or the position. Deterministic: the
/// same surface and parameters give bit-identical skeletons (CGAL's collapse order depends on
/// memory addresses; the implementation allocates CGAL's internal Polyhedron from a monotonic
/// arena so that address order is creation order). Memory: CGAL's objects are released only at the end of the
/// call (SkeletonReport::scratchBytes; 1.4 MB for a 4896-triangle tube).
#include "sim/mesh/tet_mesh.hpp"
#include "sim/mesh/tri_mesh.hpp"
#include "sim/skeleton/skeleton.hpp"

#include <cstddef>
#include <string>

namespace viscera::bake {

struct SkeletonParams {
    /// During remeshing a triangle with an angle above this is split, degrees, in (90, 180).
    double maxTriangleAngleDeg = 110.0;
    /// Edges shorter than this × bounding-box diagonal are collapsed, in (0, 0.1].
    double minEdgeLengthRel = 0.002;
    /// Contraction stops when the area change of one iteration is below this × the original
    /// area, in (0, 1).
    double areaVariationFactor = 1e-4;
    /// Cap on contraction iterations, >= 1.
    size_t maxIterations = 500;
    /// w_H of TAOZ12: lower contracts faster with a lower-quality skeleton, > 0.
    double qualitySpeedTradeoff = 0.1;
    /// Attract the flow to the Voronoi poles (medial axis approximation) so the skeleton is
    /// centred in tubes.
    bool mediallyCentered = true;
    /// w_M of TAOZ12 (used when mediallyCentered), > 0.
    double mediallyCenteredSpeedTradeoff = 0.2;
    /// Prefixes error messages: the source file or body, e.g. "vessel.obj: surface is not closed: ...".
    std::string label = "bake::extractSkeleton()";
};

struct SkeletonReport {
    size_t surfaceVertices = 0; ///< vertices referenced by the surface's triangles
    size_t surfaceTriangles = 0;
    size_t nodes = 0, edges = 0;
    int32_t components = 0; ///< connected components of the skeleton graph
    int64_t cycleRank = 0;  ///< independent loops (the genus for a connected closed surface)
    /// Surface vertices that CGAL's correspondence did not list (mapped to the nearest node);
    /// expected 0.
    size_t unlistedVertices = 0;
    size_t scratchBytes = 0; ///< memory CGAL allocated during the call (monotonic arena)
    double seconds = 0;      ///< wall time of the whole call
};

struct SkeletonResult {
    sim::Skeleton skeleton;
    SkeletonReport report;
};

/// Skeleton of a closed triangle surface. skeleton.vertexNode has one entry per vertex of
/// `surface` (kNone for a vertex no triangle references).
/// Throws viscera::InputError "<label>: <rule>" naming the element (indices of `surface`) when:
/// there are no triangles; a triangle is degenerate (collinear vertices); an edge is shared by
/// more than two triangles or by two with the same direction (non-manifold / inconsistently
/// oriented); an edge belongs to one triangle only (not closed); a vertex's triangles form more
/// than one fan (non-manifold vertex); two triangles intersect; the enclosed volume is zero.
/// Either orientation is accepted. Throws std::invalid_argument naming the SkeletonParams field
/// when a parameter is out of range.
/// Cost: a sparse solve per iteration on the contracting surface (tens of iterations); 0.4 s
/// for a 4896-triangle tube (1.4 s under load) on the build machine, recorded by the skeleton test.
SkeletonResult extractSkeleton(const sim::TriMesh& surface, const SkeletonParams& params = {});

/// Skeleton of the boundary of a tet mesh; skeleton.vertexNode has one entry per mesh vertex:
/// the node of a boundary vertex, kNone for an interior one (mapNodesToSkeleton() then maps
/// the interior nodes). Same errors as above, the element indices being those of
/// mesh.boundary(). Builds the mesh's adjacency level 3 if needed (hence non-const).
SkeletonResult extractSkeleton(sim::TetMesh& mesh, const SkeletonParams& params = {});

} // namespace viscera::bake
