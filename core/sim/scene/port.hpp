#pragma once
/// Trocar ports: an instrument (or probe, or the laparoscope) inserted through a point of the
/// abdominal or pelvic wall. Its shaft always passes through the port; what is left to move is
/// the four port degrees of freedom: pitch and yaw about the port, insertion (port to tip) and
/// roll about the shaft.
///
/// scene.json, on an instrument, a probe ("tools") or the laparoscope:
///   "port": {"position": [0.07, -0.08, 0.10], "insertion": [0.02, 0.25], "max_angle_deg": 60,
///            "shaft_length": 0.36, "mode": "robotic"}
///   position       m, scene: the port (the fulcrum; the remote centre of motion of a robot)
///   insertion      m, port to tip: [min, max], 0 < min < max <= 0.5
///   max_angle_deg  the shaft's largest angle from its rest axis (port → rest tip), (0, 89]
///   shaft_length   m, handle to tip (laparoscopic mode: the lever outside is shaft_length −
///                  insertion), >= insertion max + 0.05 and <= 1
///   mode           how a master drives it (default "laparoscopic"):
///     laparoscopic  the master holds the handle outside the body; the shaft pivots about the
///                   port, so the tip moves opposite to the hand (the fulcrum effect), scaled by
///                   the lever ratio insertion / (shaft_length − insertion); forces reach the
///                   hand through the same lever (handForce).
///     robotic       the master places the tip, scaled, without inversion (remote centre of
///                   motion); the tip is then held to the port's limits (constrain).
/// Units SI. All functions are pure, allocation-free and safe on the servo thread; non-finite
/// input gives the port's rest pose, never NaN.
#include <Eigen/Core>

#include <string>

namespace viscera::sim {

using Vec3 = Eigen::Vector3d;

enum class PortMode { Laparoscopic, Robotic };

struct PortDesc {
    bool declared = false;
    Vec3 position = Vec3::Zero();
    double insertionMin = 0.02; ///< m
    double insertionMax = 0.30; ///< m
    double maxAngleDeg = 60;    ///< deg from the rest axis
    double shaftLength = 0.36;  ///< m, handle to tip
    PortMode mode = PortMode::Laparoscopic;
};

const char* portModeName(PortMode mode);

/// Empty when `tip` (a tool's rest tip) lies within the port's insertion range; else the rule it
/// breaks ("lies 0.41 m from its port, outside the port's insertion [0.02, 0.3]"). A rule
/// between two fields (the tip and the port), checked where the scene is assembled.
std::string restTipError(const PortDesc& port, const Vec3& tip);

/// A shaft through a port.
struct PortPose {
    Vec3 tip = Vec3::Zero();
    Vec3 direction = -Vec3::UnitZ(); ///< unit, from the port towards the tip (shaft direction)
    double insertion = 0;            ///< m, port to tip
    bool insertionLimited = false;   ///< the target lay beyond [insertionMin, insertionMax]
    bool angleLimited = false;       ///< the target lay beyond max_angle_deg from the axis
};

/// A port with its rest axis (unit, port → the tool's rest tip), as the run time uses it.
struct PortFrame {
    PortDesc desc;
    Vec3 axis = -Vec3::UnitZ();
    /// Laparoscopic: handle metres per device metre across the axis, chosen so that at the rest
    /// insertion the tip moves `motionScale` scene metres per device metre sideways (opposite to
    /// the hand); along the axis the handle moves motionScale (handleMove).
    double handScale = 1.0;
    Vec3 restTip = Vec3::Zero();
    Vec3 restHandle = Vec3::Zero(); ///< laparoscopic: the handle when the tip is at restTip
};

/// The frame of `port` for a tool whose rest tip is `restTip` (its track's first key, its start).
/// `motionScale`: the device mapping's scene metres per device metre.
PortFrame makePortFrame(const PortDesc& port, const Vec3& restTip, double motionScale);

/// Laparoscopic: how far the handle moves for a master's move `deviceMove` (device metres, in the
/// scene's axes): along the rest axis by `motionScale` (the tip slides in as far), across it by
/// handScale (the tip then moves motionScale the other way at the rest insertion).
Vec3 handleMove(const PortFrame& port, const Vec3& deviceMove, double motionScale);

/// The pose nearest `target` that the port allows: the shaft through the port towards the target,
/// turned back to max_angle_deg from the axis (then the insertion is the target's projection on
/// the turned shaft), the insertion clamped to its range. A target behind the port (outside the
/// body) gives the shortest insertion.
PortPose constrainToPort(const PortFrame& port, const Vec3& target);

/// Laparoscopic: the tip of a shaft through the port whose handle end is at `handle` (then
/// constrained). The handle on the far side of the port makes the tip move opposite to it.
PortPose fulcrumTip(const PortFrame& port, const Vec3& handle);
/// Laparoscopic: where the handle is when the tip is at `tip` (the inverse of fulcrumTip).
Vec3 fulcrumHandle(const PortFrame& port, const Vec3& tip);

/// Laparoscopic: the force the hand feels at the handle for a force `tipForce` on the tip of a
/// shaft at `pose` through the port: the part along the shaft unchanged, the part across it
/// reversed and scaled by the lever ratio insertion / (shaft_length − insertion). Robotic: the
/// tip force itself.
Vec3 handForce(const PortFrame& port, const PortPose& pose, const Vec3& tipForce);

/// Distance (m) from the port to the shaft's line segment from `tip` back `length` along
/// −direction: 0 when the shaft passes through the port.
double shaftDistanceToPort(const Vec3& port, const Vec3& tip, const Vec3& direction, double length);

/// The roll (rad) of an orientation about the unit shaft axis `axis`: the twist part of the
/// rotation `q` (w, x, y, z) about that axis, in (−π, π].
double twistAbout(const Eigen::Vector4d& wxyz, const Vec3& axis);

} // namespace viscera::sim
