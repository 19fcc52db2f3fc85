#pragma once
/// What the port tool draws (studio viewport, authoring only) [issue 57 item 1]: a trocar port's
/// reachable workspace as a wire cone, and the task targets its instrument must reach as small
/// crosses, green where the port reaches them and red where it does not.
#include "render/scene_view.hpp"
#include "sim/scene/port.hpp"

#include <array>
#include <utility>
#include <vector>

namespace viscera::studio {

/// Two unit vectors perpendicular to unit `a` and to each other.
std::pair<sim::Vec3, sim::Vec3> basisAbout(const sim::Vec3& a);

/// A ring of `n` nodes appended to `nodes` and closed by `edges`: centre `c`, radius `r`, in the
/// plane of unit `u` and `v`.
void addRing(std::vector<sim::Vec3>& nodes, std::vector<std::array<int32_t, 2>>& edges, const sim::Vec3& c,
             const sim::Vec3& u, const sim::Vec3& v, double r, int n);

/// The workspace of `port` as thin tubes: 16 lines from the port (the apex) along the cone's
/// surface, max_angle_deg about the rest axis, out to the insertion maximum; rims at the
/// insertion minimum and maximum (the tip reaches the shell between them); a short stub along
/// the axis outside the body (the shaft's side). Colour light cyan; tube radius 0.4 % of the
/// insertion maximum. Named "port workspace". Empty mesh for a non-finite port.
render::RenderMesh portWorkspaceMesh(const sim::PortFrame& port, uint32_t material);

/// A task point to reach and whether the port reaches it.
struct ReachMarker {
    sim::Vec3 point = sim::Vec3::Zero(); ///< m
    bool reached = true;
};

/// Each marker as a three-axis cross of half size `size` (m): green reached, red not. Named
/// "port targets". Non-finite points are skipped.
render::RenderMesh reachMarkersMesh(const std::vector<ReachMarker>& markers, double size, uint32_t material);

/// The port gizmo: a handle per world axis from `at`, `length` (m) long, x red, y green, z blue,
/// each its own mesh named "port gizmo x", "… y", "… z" (in axis order). Empty for a non-finite
/// point.
std::vector<render::RenderMesh> portGizmoMeshes(const sim::Vec3& at, double length, uint32_t material);

} // namespace viscera::studio
