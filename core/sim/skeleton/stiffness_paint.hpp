#pragma once
/// Skeleton-based stiffness painting [A §4.3.5, eq. 4.26–4.28]: brush strokes select mesh nodes
/// through the skeleton (a skeleton node p_j inside the brush selects its Π_j) and add a poly6
/// kernel weight to them. The result is one stiffness weight per node, TetBodyDesc::nodeWeights
/// (a tet's weight is the mean of its nodes' and divides its XPBD compliances, α/w).
///
/// Sign of the kernel. [A eq. 4.28] prints w(v) = 315/(64π h⁹)·(v² − h²)³ for v < h, which is
/// <= 0 inside the support: every stroke would soften and a weight could never be raised. We use
/// the standard poly6 kernel (Müller et al. 2003) that the text names,
///     W_poly6(v, h) = 315/(64π h⁹)·(h² − v²)³  for 0 <= v < h,   0 for v >= h,
/// which is >= 0, maximal at v = 0 (315/(64π h³)) and integrates to 1 over the ball of radius h.
/// Softening is expressed by a negative stroke amplitude instead.
#include "sim/mesh/tri_mesh.hpp"
#include "sim/skeleton/skeleton.hpp"

#include <string>
#include <vector>

namespace viscera::sim {

/// W_poly6(v, h) as documented above, 1/m³. Throws std::invalid_argument when h is not finite
/// and > 0, or v is not finite and >= 0.
double poly6Kernel(double v, double h);

/// How a stroke's amplitude scales the kernel.
enum class BrushScale {
    /// Added weight a·W(v,h)/W(0,h) = a·(1 − v²/h²)³: `amplitude` is the weight added at the
    /// brush centre (dimensionless). The default: an artist's "+2 at the centre".
    Peak,
    /// Added weight a·W(v,h), eq. 4.26 as printed for a = 1 (W in 1/m³, so `amplitude` is in m³).
    Kernel,
};

/// What a stroke does to the weight w of each selected node, with k its kernel factor at the node
/// (BrushScale: Peak gives (1 − v²/h²)³ ∈ [0, 1] at distance v, Kernel gives W_poly6(v, h)):
///   Add       w += a·k                               (eq. 4.26)
///   Subtract  w −= a·k
///   Mix       w += t·(target − w),  t = min(1, a·k)  (towards a target weight)
///   Smooth    w += t·(w̄ − w),       t = min(1, a·k)  (w̄: mean weight of the node's mesh
///                                                      neighbours before the stroke)
/// Mix and Smooth take a >= 0 as the brush's strength; t never overshoots.
enum class BrushMode { Add, Subtract, Mix, Smooth };

/// Which nodes of a tet body a stroke selects (the kernel is always taken at the node's own
/// distance from the centre, so a node outside the sphere never changes):
///   Skeleton  the members Π_j of every skeleton node p_j strictly inside the sphere [A eq. 4.26]:
///             a brush on the surface of a thick body whose skeleton lies deeper than its radius
///             selects nothing;
///   Sphere    those, and every node strictly inside the sphere: the surface nodes the artist
///             touches as well (the studio's default for new strokes).
enum class BrushReach { Skeleton, Sphere };

/// Accepted brush radii, metres (keeps 1/h⁹ and the peak 315/(64π h³) finite).
inline constexpr double kMinBrushRadius = 1e-6;
inline constexpr double kMaxBrushRadius = 1e3;

/// One brush stroke: an implicit sphere (centre c, support radius h) and an amplitude.
struct BrushStroke {
    Vec3 center = Vec3::Zero(); ///< c, metres, mesh frame
    double radius = 0.01;       ///< h, metres, in [kMinBrushRadius, kMaxBrushRadius]
    double amplitude = 1.0;     ///< weight to add (see BrushScale); < 0 softens
    BrushScale scale = BrushScale::Peak;
    BrushMode mode = BrushMode::Add;
    double target = 1.0;                     ///< Mix: the weight approached (finite, > 0)
    BrushReach reach = BrushReach::Skeleton; ///< tet bodies only (a surface's polygon paint is by sphere)
};

/// The mesh neighbours of every node (its edges), compressed: node i's are
/// members[start[i] .. start[i+1]). What the Smooth mode averages over.
struct NodeNeighbours {
    std::vector<int32_t> start, members;
    size_t nodeCount() const { return start.empty() ? 0 : start.size() - 1; }
};
/// From the tets' edges. O(#T log #T).
NodeNeighbours nodeNeighbours(const TetMesh& mesh);
/// From the triangles' edges (a fascia's polygon paint).
NodeNeighbours nodeNeighbours(const TriMesh& mesh);

struct PaintParams {
    double baseWeight = 1.0; ///< W before the first stroke, > 0
    /// Weights are clamped to [minWeight, maxWeight] after every stroke (0 < min <= base <= max).
    /// The floor keeps every weight positive: XPBD divides compliances by it.
    double minWeight = 1e-3;
    double maxWeight = 1e6;
    std::string origin = "sim::bakeStiffnessPaint()"; ///< prefixes error messages
};

/// Figures of a bake, for the studio log.
struct StiffnessPaintReport {
    std::vector<size_t> strokeSelected;     ///< per stroke: nodes selected through the skeleton
    std::vector<size_t> strokeChanged;      ///< per stroke: selected nodes with a non-zero kernel
    size_t clampedLow = 0, clampedHigh = 0; ///< clamp events over all strokes
    size_t fallbackNodes = 0;               ///< nodes mapped by SkeletonNodeMap's fallback
    double minWeight = 0, maxWeight = 0;    ///< of the result
};

struct StiffnessPaintResult {
    std::vector<double> weights; ///< one per mesh node, finite, in [minWeight, maxWeight]
    SkeletonNodeMap map;
    StiffnessPaintReport report;
};

/// Validates a stroke; throws std::invalid_argument "<origin>: stroke 2: radius is 0.000000 m
/// (must be in [1e-6, 1e3] m)" naming the field and the rule: centre finite, radius in range,
/// amplitude finite (>= 0 for Mix and Smooth), amplitude × peak increment finite, a Mix target
/// finite and > 0.
void validateStroke(const BrushStroke& stroke, size_t index, const std::string& origin);

/// Applies one stroke to `weights` (#n, one per node of `positions`) [A eq. 4.26]: the selected
/// nodes are ∪ Π_j over skeleton nodes with |p_j − c| < h (and, with BrushReach::Sphere, every
/// node with |x_i − c| < h); each selected node i changes by the
/// stroke's mode (BrushMode) with k = kernel(|x_i − c|, h) (zero outside the sphere), then the
/// selected nodes are clamped to [minWeight, maxWeight]. `neighbours` (of the same nodes) is
/// needed by Smooth only. Updates the stroke figures of `report`. Throws std::invalid_argument
/// on a bad stroke or parameters, or when a result is not finite (weights are then unchanged).
void applyBrushStroke(const std::vector<Vec3>& positions, const Skeleton& skeleton, const SkeletonNodeMap& map,
                      const BrushStroke& stroke, const PaintParams& params, std::vector<double>& weights,
                      StiffnessPaintReport* report = nullptr, const NodeNeighbours* neighbours = nullptr);

/// Polygon paint of a triangle surface (fascia) [A §4.3.5, Fig. 4.11]: the same stroke on the
/// vertices directly, no skeleton. The selected vertices are those strictly inside the brush
/// sphere (|x_i − c| < h); each changes by the stroke's mode with k = kernel(|x_i − c|, h), then is
/// clamped. `positions` are the surface's rest positions, `neighbours` (nodeNeighbours of the
/// triangles) is needed by Smooth only. Throws as applyBrushStroke.
void applySurfaceBrushStroke(const std::vector<Vec3>& positions, const BrushStroke& stroke, const PaintParams& params,
                             std::vector<double>& weights, StiffnessPaintReport* report = nullptr,
                             const NodeNeighbours* neighbours = nullptr);

/// `strokes` in order on W = baseWeight, one weight per vertex of `mesh` (SurfaceDesc::nodeWeights).
/// Throws std::invalid_argument naming the stroke/field on bad input.
std::vector<double> bakeSurfacePaint(const TriMesh& mesh, const std::vector<BrushStroke>& strokes,
                                     const PaintParams& params = {}, StiffnessPaintReport* report = nullptr);

/// Maps every node of `mesh` to the skeleton (mapNodesToSkeleton) and applies `strokes` in order to
/// W = baseWeight. Throws std::invalid_argument naming the stroke/field on bad input.
/// Cost: O(n·m) for the map, O(|selected|) per stroke.
StiffnessPaintResult bakeStiffnessPaint(const TetMesh& mesh, const Skeleton& skeleton,
                                        const std::vector<BrushStroke>& strokes, const PaintParams& params = {});

} // namespace viscera::sim
