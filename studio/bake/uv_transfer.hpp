#pragma once
/// Texture-coordinate transfer from render anatomy (the source: parts with per-corner UVs, seams
/// and islands) to a remeshed surface (the target) [A §3.3]. Three methods, measured the same way:
///
///   closest point  [A §3.3.3, first part]: every target vertex takes the UV of its closest point
///                  on the source; a target triangle over a seam interpolates between islands;
///   island label   [A §3.3.3]: each target triangle takes the island that covers most of it
///                  (sampled) and every corner projects onto that island only; triangles over a
///                  seam inside one island still stretch (Fig. 3.4 case 3);
///   seam cutting   [A §3.3.4, Algorithm 1]: the target is cut along the source's seams. Each
///                  target vertex takes the chart of its closest source point (an island, or a
///                  half of an island with a seam inside it); an edge between two charts is split
///                  where the distances to the two charts are equal (bisection: this also places
///                  the cut where two overlapping parts meet, off both), triangles are split into
///                  pieces of one chart, and a vertex close to a cut point is snapped onto it
///                  instead of leaving a sliver. The chart borders are held hard while the cut
///                  mesh is remeshed, and each target triangle takes its UVs from one host chart
///                  (its centroid's), each corner at its closest point on that chart.
///
/// Measures [issue 16 item 2]: target triangles spanning two UV islands (sample points of the
/// triangle projected to different islands) and triangles a seam crosses (any seam, also one inside
/// an island), the per-face angle and area distortion of the
/// transferred UVs against the source's own map (the singular values σ1 ≥ σ2 of the map from the
/// target triangle through its UVs back onto the host source triangle: angle σ1/σ2, area σ1σ2;
/// both 1 for a perfect transfer), and the UV error at sampled surface points against the UV of
/// their closest source point.
#include "bake/remesh.hpp"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace viscera::bake {

enum class UvTransferMethod { ClosestPoint, IslandLabelled, SeamCutting };

/// "closest-point", "island-labelled", "seam-cutting".
std::string_view uvTransferMethodName(UvTransferMethod method);

/// The source of a transfer: every part with UVs, welded per part (vertices at one position are
/// one point), its islands (triangles connected across edges whose two sides have the same UVs)
/// and seam edges (a point pair shared by two triangles whose UVs differ there), with a search
/// tree for closest points. Throws InputError naming the part when a part has no UVs, a UV count
/// other than one per triangle, or a UV that is not finite.
class UvSource {
public:
    explicit UvSource(const std::vector<RemeshPart>& parts);
    ~UvSource();
    UvSource(const UvSource&) = delete;
    UvSource& operator=(const UvSource&) = delete;

    size_t triangleCount() const;
    size_t islandCount() const;
    size_t seamEdgeCount() const;
    /// The island of source triangle t (numbered over all parts).
    int island(size_t t) const;

    struct Hit {
        size_t triangle = 0;     ///< source triangle (over all parts)
        Eigen::Vector3d bary{};  ///< barycentric coordinates of the point in it
        Eigen::Vector3d point{}; ///< the closest point, m
        Eigen::Vector2d uv{};    ///< its UV (the triangle's corner UVs interpolated)
        double distance = 0;     ///< m
    };
    /// Closest point on the whole source.
    Hit closest(const Eigen::Vector3d& p) const;
    /// Closest point on one island.
    Hit closestOnIsland(const Eigen::Vector3d& p, int island) const;
    /// Charts: the islands, an island with a seam inside it split in two along that seam (a tube
    /// unwrapped into one island: two half tubes), so that the UVs are continuous on each chart.
    size_t chartCount() const;
    int chart(size_t t) const;
    /// Closest point on one chart.
    Hit closestOnChart(const Eigen::Vector3d& p, int chart) const;
    /// Closest point among `triangles`.
    Hit closestAmong(const Eigen::Vector3d& p, const std::vector<size_t>& triangles) const;
    /// The corner positions and UVs of source triangle t.
    std::array<Eigen::Vector3d, 3> corners(size_t t) const;
    const CornerUv& cornerUv(size_t t) const;
    /// The triangle across edge k (corners k, k + 1) of triangle t, seam or not; −1 at a border.
    int32_t neighbourAcross(size_t t, int k) const;

    struct SeamSegment {
        Eigen::Vector3d a{}, b{};
        Eigen::Vector3d normal{}; ///< unit: the mean normal of the two triangles
    };
    const std::vector<SeamSegment>& seamSegments() const;
    /// Indices of seam segments whose bounding box, grown by `margin`, meets the box [lo, hi].
    void seamSegmentsNear(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double margin,
                          std::vector<int>& out) const;
    /// Distance from p to the nearest seam segment within `margin` of it (infinity when none).
    double distanceToSeam(const Eigen::Vector3d& p, double margin) const;

private:
    struct Impl;
    std::unique_ptr<Impl> m_impl;
};

/// A target surface with per-corner UVs: seams are edges whose two triangles' corner UVs differ.
struct UvMesh {
    sim::TriMesh mesh;
    std::vector<CornerUv> uv;                      ///< one per triangle
    std::vector<std::array<int32_t, 2>> seamEdges; ///< seam cutting: the edges on the source's seams
    /// Seam cutting: the edges between two charts (the seam edges, and where the two halves of an
    /// island with a seam inside it meet): what the remesher holds.
    std::vector<std::array<int32_t, 2>> chartBorders;
};

/// Cuts `target` along the source's seams and chart borders (Algorithm 1, lines 3–8 and 13–15):
/// every triangle of the result lies on one chart; lists its chart borders and seam edges; no
/// UVs yet (uv empty).
UvMesh cutAlongSeams(const UvSource& source, const sim::TriMesh& target, const SeamCutParams& params,
                     SeamCutReport* report = nullptr);

/// Whether edge (a, b) of a cut target is a seam edge: it lies on a source seam, or its two
/// triangles (centroids c0, c1) lie on different islands (parts that meet). What the remesher holds.
bool isSeamEdge(const UvSource& source, const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c0,
                const Eigen::Vector3d& c1);

/// UVs for every triangle of `target` by `method`. SeamCutting expects a target already cut
/// (cutAlongSeams, then remeshed with the chart borders hard): it only applies the host-chart rule.
std::vector<CornerUv> transferUv(const UvSource& source, const sim::TriMesh& target, UvTransferMethod method);

struct UvTransferStats {
    size_t triangles = 0;
    /// Triangles over two islands: an inside sample point is closer to another island than to the
    /// centroid's by more than 5 % of the triangle's longest edge (closer by less, both islands are
    /// as good a host: a crease where parts meet, a ridge).
    size_t spanningIslands = 0;
    size_t seamCrossed = 0; ///< triangles an edge of which a seam crosses (also seams inside one island)
    size_t flipped = 0;     ///< triangles whose UV image is mirrored or degenerate against the source's
    /// Angle distortion σ1/σ2 (1 = conformal to the source map): median, 95th percentile, max.
    double angleP50 = 0, angleP95 = 0, angleMax = 0;
    /// Area distortion σ1σ2 as a factor away from 1 (max(a, 1/a)): median, 95th percentile, max.
    double areaP50 = 0, areaP95 = 0, areaMax = 0;
    /// Share of triangles over the stretch threshold: angle > 2, area factor > 2, or flipped.
    double overThreshold = 0;
    /// UV error at sampled surface points against their closest source point's UV (UV units).
    double uvErrorMean = 0, uvErrorP95 = 0, uvErrorMax = 0;
    size_t samples = 0;
    std::vector<double> faceStretch; ///< per triangle: max(angle, area factor); infinity when flipped
};

/// Measures a transfer. `samples` surface points (area-weighted, deterministic) for the UV error.
UvTransferStats measureUvTransfer(const UvSource& source, const sim::TriMesh& target, const std::vector<CornerUv>& uv,
                                  size_t samples = 20000);

/// Stretch threshold of UvTransferStats::overThreshold and of the studio's heat map.
inline constexpr double kUvStretchThreshold = 2.0;

/// Writes a surface with per-corner UVs as Wavefront OBJ (v, vt, f v/vt), atomically.
void writeObjWithUv(const std::string& path, const sim::TriMesh& mesh, const std::vector<CornerUv>& uv);

} // namespace viscera::bake
