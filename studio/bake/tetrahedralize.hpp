#pragma once
/// Volume meshing of a closed surface into a tetrahedral mesh (Delaunay refinement of a
/// polyhedral domain with protected sharp features, followed by optional optimizers).
///
/// Sizes are in metres. A size of 0 means "automatic": derived from the diagonal D of the
/// surface's bounding box as documented per field; MeshingReport::resolved holds the values used.
/// The result is deterministic for a given surface, parameters and seed (single-threaded). CGAL's
/// default random generator (thread-local) is reseeded during the call and restored afterwards.
#include "sim/mesh/tet_mesh.hpp"
#include "sim/mesh/tri_mesh.hpp"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

namespace viscera::bake {

struct MeshingParams {
    /// Lower bound on the angles of boundary triangles, degrees, in (0, 30].
    double facetAngleDeg = 25.0;
    /// Upper bound on the circumradius of boundary triangles, m; 0 = D / 20.
    double facetSize = 0.0;
    /// Upper bound on the distance between a boundary triangle's circumcentre and the input
    /// surface, m; 0 = facetSize / 10.
    double facetDistance = 0.0;
    /// Upper bound on the ratio circumradius / shortest edge of a tet, >= 2.
    double cellRadiusEdgeRatio = 3.0;
    /// Upper bound on the circumradius of a tet, m; 0 = facetSize.
    double cellSize = 0.0;
    /// Sampling distance along protected sharp edges, m; 0 = facetSize.
    double edgeSize = 0.0;
    /// Edges whose two triangle normals differ by more than this angle (degrees) are protected
    /// as sharp features (box edges stay sharp); <= 0 protects none. In [0, 180).
    double featureAngleDeg = 60.0;
    /// Optimizers, run in this order after refinement.
    bool odt = false;
    bool lloyd = false;
    bool perturb = true;
    bool exude = true;
    /// Iteration cap for odt / lloyd; 0 = until they converge.
    int smoothingMaxIterations = 0;
    /// After the first refinement, seed the input surface the mesh missed (no boundary vertex
    /// within 1.5 facet sizes: a thin part the refinement never met) and refine again.
    bool seedMissedSurface = true;
    /// Seed of the random generators used by the mesher and the optimizers.
    uint32_t seed = 0;
    /// Refuse parameters whose cell size would give more tets than this (estimated from the
    /// enclosed volume and cellSize) instead of running for hours.
    size_t maxEstimatedTets = 2'000'000;
    /// Prefixes error messages: the source file, for instance ("liver.obj: surface is not
    /// closed: ...").
    std::string label = "bake::tetrahedralize()";
};

enum class MeshingStage { CheckSurface, BuildDomain, Refine, Odt, Lloyd, Perturb, Exude, Export };

/// "check surface", "build domain", "refine", "odt", "lloyd", "perturb", "exude", "export".
std::string_view stageName(MeshingStage stage);

/// Called on the calling thread at the start of each stage and once at the end with
/// (Export, 1.0). `fraction` is the estimated overall progress in [0, 1].
using ProgressCallback = std::function<void(MeshingStage stage, double fraction)>;

struct MeshingReport {
    size_t vertexCount = 0;
    size_t tetCount = 0;
    size_t boundaryTriangleCount = 0; ///< boundary facets of the tet mesh
    size_t featureEdgeCount = 0;      ///< input edges protected as sharp features
    /// Surface points seeded after the first refinement because no boundary vertex lay within 1.5
    /// facet sizes of them (thin parts the first pass missed); 0: the first pass covered it all.
    size_t missedSurfaceSeeds = 0;
    sim::QualityReport quality;
    double tetVolume = 0;       ///< sum of tet volumes, m^3
    double surfaceVolume = 0;   ///< volume enclosed by the input surface, m^3
    double volumeRelError = 0;  ///< (tetVolume - surfaceVolume) / surfaceVolume
    MeshingParams resolved;     ///< parameters with the automatic values filled in
    double refineSeconds = 0;   ///< surface checks, domain construction, Delaunay refinement
    double optimizeSeconds = 0; ///< odt, lloyd, perturb, exude
    double totalSeconds = 0;
};

struct TetrahedralizeResult {
    /// Positively oriented tets, only the cells inside the domain, no unreferenced vertices.
    std::unique_ptr<sim::TetMesh> mesh;
    MeshingReport report;
};

/// Tetrahedralizes the volume enclosed by `surface`.
/// Throws viscera::InputError when the surface is unusable, naming the rule and the element
/// (indices are those of `surface`), e.g. "<label>: surface is not closed: edge (3, 7) belongs to
/// only one triangle (12)". Rules: at least one triangle; no degenerate (zero-area) triangle;
/// every edge shared by exactly two triangles that traverse it in opposite directions (closed,
/// consistently oriented); every vertex a single fan of triangles (manifold); no self-intersecting
/// triangles; a non-zero enclosed volume; sizes that give at most maxEstimatedTets. Either
/// orientation (outward or inward) is accepted. Throws std::invalid_argument naming the field
/// when a parameter is out of range.
/// Cost: dominated by refinement and perturbation, roughly linear in the number of tets.
TetrahedralizeResult tetrahedralize(const sim::TriMesh& surface, const MeshingParams& params,
                                    ProgressCallback progress = {});

} // namespace viscera::bake
