#pragma once
/// What the stiffness paint tool draws besides the body (studio viewport, authoring only):
/// the weight ramp, the curve skeleton as thin tubes, and a cut through the body that shows the
/// weights of interior nodes. All in the body's rest frame (the body is shown at rest while it
/// is painted).
#include "render/scene_view.hpp"
#include "sim/mesh/tet_mesh.hpp"
#include "sim/skeleton/skeleton.hpp"

#include <Eigen/Core>

#include <vector>

namespace viscera::studio {

/// The ramp of weight w against the base weight, RGBA: log(w / base) over a factor of 4 either
/// way, blue softer, grey at the base, red stiffer; alpha 0.9 for a painted node and 0.35 for
/// one exactly at the base (unpainted).
Eigen::Vector4f weightColour(double w, double base);

/// The skeleton's edges as six-sided tubes of radius `radius` (m) and its nodes' positions,
/// coloured by an opaque yellow overlay. Empty mesh for an empty skeleton.
render::RenderMesh skeletonMesh(const sim::Skeleton& skeleton, float radius, uint32_t material);

/// `edges` between `nodes` (m) as six-sided tubes of radius `radius` (m), named `name`, in one
/// opaque overlay colour `rgba`. Empty mesh for no edges.
render::RenderMesh lineTubes(std::vector<sim::Vec3> nodes, std::vector<std::array<int32_t, 2>> edges, double radius,
                             const char* name, const Eigen::Vector4f& rgba, uint32_t material);

/// The brush's outline on the surface: a flat ring of radius `radius` (m) about `centre` in the
/// plane normal to `normal` (drawn surface frame), its band 4 % of the radius wide (at least
/// 0.15 mm), lifted 1 % of the radius off the surface along the normal so that it is not hidden
/// in it; 48 segments, opaque light-yellow overlay, double-sided. Named "brush".
render::RenderMesh brushRingMesh(const Eigen::Vector3d& centre, const Eigen::Vector3d& normal, double radius,
                                 uint32_t material);

/// The authoring look's ground grid under a scene of bounds [lo, hi] (m; z up): lines at a round
/// step (1, 2 or 5 × 10^k, about a fifth of the scene's larger horizontal size) over 1.5 times
/// that size, in the plane z = lo.z, as thin grey tubes. Named "grid".
render::RenderMesh gridMesh(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, uint32_t material);

/// The twelve edges of the box [lo, hi] as thin light-blue tubes (the selection's outline),
/// radius 0.4 % of the box's diagonal. Named "selection" unless `name` says otherwise.
render::RenderMesh boxOutlineMesh(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, uint32_t material,
                                  const char* name = "selection",
                                  const Eigen::Vector4f& rgba = {0.35f, 0.75f, 1.0f, 1.0f});

/// A plane {x : n·x = offset} with unit normal n; the side n·x > offset is cut away.
struct CutPlane {
    Eigen::Vector3d normal = Eigen::Vector3d::UnitX();
    double offset = 0;
};

/// The section of `mesh` by `plane`: one or two triangles per cut tet, each vertex on a tet edge
/// with the weight interpolated linearly between the edge's nodes and coloured by weightColour.
/// Faces towards the kept side's outside (−n), drawn double-sided.
render::RenderMesh sliceMesh(const sim::TetMesh& mesh, const std::vector<double>& weights, double base,
                             const CutPlane& plane, uint32_t material);

/// Face mask of a body render mesh for the cut-away: faces whose rest centroid lies on the cut
/// side are not drawn.
std::vector<uint8_t> cutAwayMask(const render::RenderMesh& body, const CutPlane& plane);

} // namespace viscera::studio
