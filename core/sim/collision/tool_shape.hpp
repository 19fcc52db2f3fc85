#pragma once
/// Rigid tools as implicit shapes driven by device poses [A §5.2]: a union of capsules (a sphere
/// is a capsule of zero length) given in the tool frame and placed by a rigid pose. Factories for
/// a sphere, a capsule (cylinder with round ends, e.g. an instrument shaft) and grasper jaws (two
/// capsules hinged at the tip of the shaft, opened by an angle).
///
/// Units: metres; the pose maps tool-frame points to the world frame. Distances are signed:
/// negative inside the tool. Cost of a query O(#capsules).
#include "sim/mesh/tri_mesh.hpp"

#include <Eigen/Geometry>

#include <string>
#include <vector>

namespace viscera::sim {

struct Capsule {
    Vec3 a = Vec3::Zero(), b = Vec3::Zero(); ///< axis end points, m (equal: a sphere)
    double radius = 0.005;                   ///< m, > 0
};

/// Signed distance from p to the capsule surface (negative inside), m.
double signedDistance(const Capsule& c, const Vec3& p);

/// Closest point q on a capsule's axis to p and the unit direction from q to p (any unit vector
/// orthogonal to the axis when p lies on it).
struct AxisPoint {
    Vec3 onAxis = Vec3::Zero();
    Vec3 direction = Vec3::UnitZ();
    double distance = 0; ///< |p − onAxis|, m
};
AxisPoint closestAxisPoint(const Capsule& c, const Vec3& p);

class ToolShape {
public:
    using Pose = Eigen::Isometry3d;

    /// Sphere of radius r centred at the tool origin. Throws std::invalid_argument on r <= 0.
    static ToolShape sphere(double radius);
    /// Capsule along the tool's x axis from −halfLength to +halfLength. Throws on radius <= 0 or
    /// halfLength < 0.
    static ToolShape capsule(double halfLength, double radius);
    /// Grasper jaws: two capsules of the given length and radius hinged at the tool origin,
    /// pointing along +x and opened by ±opening/2 about the tool's y axis (opening in radians,
    /// 0 = closed, both jaws on the x axis). Throws on bad sizes or opening outside [0, π).
    static ToolShape jaws(double length, double radius, double opening);
    /// Any union of capsules in the tool frame (at least one, radii > 0, finite).
    static ToolShape fromCapsules(std::vector<Capsule> parts, const std::string& name = "tool");

    const std::string& name() const { return m_name; }
    const std::vector<Capsule>& localParts() const { return m_local; }
    /// World-frame capsules at the current pose.
    const std::vector<Capsule>& parts() const { return m_world; }

    /// Sets the pose (tool frame → world). Non-finite poses are ignored (the tool stays).
    void setPose(const Pose& pose);
    const Pose& pose() const { return m_pose; }
    /// Opening angle of jaws (radians, clamped to [0, π)); ignored by other tools.
    void setOpening(double opening);

    /// Signed distance from p to the union of parts (negative inside), m.
    double signedDistance(const Vec3& p) const;
    /// World-frame axis-aligned bounds of the parts, grown by `margin` (m).
    std::array<Vec3, 2> bounds(double margin = 0) const;

private:
    void refresh();
    std::string m_name;
    std::vector<Capsule> m_local, m_world;
    Pose m_pose = Pose::Identity();
    bool m_isJaws = false;
    double m_jawLength = 0, m_jawRadius = 0;
};

/// Pose interpolated between two poses (linear in translation, slerp in rotation), s in [0, 1].
ToolShape::Pose interpolatePose(const ToolShape::Pose& a, const ToolShape::Pose& b, double s);

} // namespace viscera::sim
