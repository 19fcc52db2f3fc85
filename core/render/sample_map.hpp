#pragma once
/// Light-sampling maps [A §6.3.2, Fig. 6.15]: the per-vertex sample classes (unpainted, 1×, 4×,
/// 8×) a RenderMesh carries in sampleMap, filled over connected regions and measured by area.
/// Everything works on the rest positions, so a map does not change as the tissue deforms.
#include "render/scene_view.hpp"
#include "sim/scene/scene.hpp"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace viscera::render {

/// The classes a vertex can carry: 0 (unpainted: the settings' uniform count), 1, 4 or 8.
bool isSampleClass(int samples);

/// Sets the class `samples` (0 erases, else 1, 4 or 8) on every vertex of the faces reachable
/// from face `seedFace` across edges whose two faces' normals differ by at most `maxAngleDeg`
/// (a sharp edge stops the fill) and, when `faceIsland` is given (one UV island id per face),
/// whose two faces lie in the same island (a UV border stops it). Returns the faces reached.
/// Throws std::invalid_argument on a bad class, face index, angle or island size.
size_t fillSampleClass(RenderMesh& mesh, size_t seedFace, int samples, float maxAngleDeg,
                       const std::vector<int32_t>& faceIsland = {});

/// Area (m², at rest) of the mesh in each class, by vertex: each vertex owns a third of its
/// faces' area. Index 0: unpainted, 1: 1×, 2: 4×, 3: 8×.
std::array<double, 4> sampleClassAreas(const RenderMesh& mesh);

/// One operation of light-sample painting on a body's surface [A §6.3.2]. Operations are kept in
/// the studio project and replayed in order on the rest positions, so a map follows the body by
/// position when its mesh is generated again.
struct SamplePaintOp {
    enum class Tool { Brush, Fill };
    Tool tool = Tool::Brush;
    int samples = 8; ///< the class painted (0 erases)
    /// Brush: the dab centres of one stroke; fill: one seed point (the fill starts at the face
    /// nearest to it). Metres, at rest.
    std::vector<Eigen::Vector3d> points;
    double radius = 0.01;    ///< brush: every vertex within this distance of a dab, m (> 0)
    double maxAngleDeg = 30; ///< fill: an edge whose faces' normals differ more stops it, [0, 180]
};

/// Checks an operation; throws std::invalid_argument "<what>: <rule>" (a bad class, no point, a
/// non-finite point, a radius not > 0, an angle outside [0, 180], a fill with more than one point).
void validateSamplePaintOp(const SamplePaintOp& op, const std::string& what);

/// Sets `samples` on every vertex within `radius` of one of `points` (rest positions); returns the
/// vertices set. Throws std::invalid_argument on a bad class.
size_t paintSampleBrush(RenderMesh& mesh, const std::vector<Eigen::Vector3d>& points, double radius, int samples);

/// The face whose rest triangle is nearest to `p` (point–triangle distance). Throws
/// std::invalid_argument for a mesh without faces.
size_t nearestFace(const RenderMesh& mesh, const Eigen::Vector3d& p);

/// Clears the sample map of `mesh` and replays `ops` in order (each validated first: nothing is
/// changed when one is bad). `faceIsland` as for fillSampleClass.
void applySamplePaint(RenderMesh& mesh, const std::vector<SamplePaintOp>& ops,
                      const std::vector<int32_t>& faceIsland = {});

/// The class of every node of a body with `nodeCount` nodes from its surface mesh (sourceVertex
/// maps render vertices to nodes); nodes off the surface get 0.
std::vector<uint8_t> nodeSampleClasses(const RenderMesh& bodySurface, size_t nodeCount);

/// What the player does with a case's sample map: sets the sample map of the render mesh of body
/// `body` from its node classes, and of every surface mesh in `surfacesOnBody` (fascia attached
/// to the body; SceneView surface indices) from the nearest body vertex at rest when it lies
/// within `tolerance` m (the layer is cut from the body's boundary, so its vertices coincide).
/// Throws std::invalid_argument when the classes do not match the body's nodes.
void applyNodeSampleClasses(SceneView& view, size_t body, const std::vector<uint8_t>& nodeClasses,
                            const std::vector<size_t>& surfacesOnBody, float tolerance);

/// applyNodeSampleClasses for body `body` named `bodyName` of a scene whose fascia are
/// `surfaces` (scene order): the layers attached to the body take its map, matched within the
/// largest of their attach distances (at least 1 µm). What the player and the studio's
/// comparison both do with a body's map.
void applyBodySampleMap(SceneView& view, size_t body, const std::string& bodyName,
                        const std::vector<uint8_t>& nodeClasses, const std::vector<sim::SurfaceDesc>& surfaces);

/// The .vsamples text format: the painted light-sample class of every node of a tet body (case
/// packages; packaging/vcase-spec.md):
///
///   vsamples 1
///   nodes <N>
///   <c>                    N lines, one class per node in node order: 0, 1, 4 or 8
///
/// '#' comments and blank lines are ignored. Errors name the origin, the line and the rule
/// ("liver.vsamples: line 5: class of node 2 is 3 (must be 0, 1, 4 or 8)").
std::vector<uint8_t> parseSampleMap(std::string_view text, const std::string& origin,
                                    std::optional<size_t> expectedNodes = std::nullopt);
/// Throws std::invalid_argument for no nodes or a value that is not a class.
std::string formatSampleMap(const std::vector<uint8_t>& classes);

} // namespace viscera::render
