#pragma once
/// The laparoscope: a camera on its own trocar port, steered by a master while the Cam pedal is
/// held (the instruments hold still meanwhile), with the head light at its tip.
///
/// scene.json:
///   "laparoscope": {"port": {...port.hpp...}, "tip": [0.0, -0.05, 0.06], "optic_deg": 30,
///                   "fov_deg": 70, "hand": "right", "motion_scale": 0.3}
///   port          the scope's trocar (its mode is ignored: a scope holder keeps the port as a
///                 remote centre of motion; insertion and angle limits hold)
///   tip           m, scene: the optic's tip at rest, within the port's insertion range
///   optic_deg     0 (forward-viewing) or 30 (the view turned 30° from the shaft), default 30
///   fov_deg       vertical field of view, [20, 120], default 70
///   hand          the master that steers it ("left", "right", "any" → the first arm), default right
///   motion_scale  scene metres of the tip per device metre while steering, (0, 10], default 0.3
/// A 30° optic looks towards the scene's −z (the surgeon's "down") at roll 0; the master's twist
/// about the shaft while steering rolls the optic. Units SI.
#include "sim/scene/port.hpp"

#include <string>

namespace viscera::sim {

struct LaparoscopeDesc {
    PortDesc port;
    Vec3 tip = Vec3::Zero();
    double opticDeg = 30;
    double fovDeg = 70;
    std::string hand = "right";
    double motionScale = 0.3;
};

/// Where the scope is and what it sees.
struct ScopePose {
    Vec3 tip = Vec3::Zero();
    Vec3 shaft = -Vec3::UnitZ(); ///< unit, port → tip
    Vec3 view = -Vec3::UnitZ();  ///< unit, the optic's viewing direction
    Vec3 up = Vec3::UnitY();     ///< unit, the image's up, perpendicular to view
    double insertion = 0;        ///< m
    double roll = 0;             ///< rad, the optic's turn about the shaft
    bool atLimit = false;        ///< held at the port's insertion or angle limit
};

/// A scope's pose for a shaft through the port towards `target` (constrained), rolled by `roll`.
ScopePose scopePose(const LaparoscopeDesc& desc, const PortFrame& port, const Vec3& target, double roll);

/// The scope's state over a session. Steering: grab() when the Cam pedal goes down, then
/// steer(move, twist) with the master's displacement (device metres) and twist (rad) since then.
class Laparoscope {
public:
    explicit Laparoscope(const LaparoscopeDesc& desc);
    void grab();
    void steer(const Vec3& deviceMove, double twist);
    const ScopePose& pose() const { return m_pose; }
    /// The Cam pedal is held (the instruments hold still); set by whoever steers.
    void setSteering(bool on) { m_steering = on; }
    bool steering() const { return m_steering; }
    const LaparoscopeDesc& desc() const { return m_desc; }
    /// m: how far the tip has moved over the session (the camera path).
    double path() const { return m_path; }

private:
    LaparoscopeDesc m_desc;
    PortFrame m_port;
    ScopePose m_pose;
    Vec3 m_grabTip = Vec3::Zero();
    double m_grabRoll = 0, m_path = 0;
    bool m_steering = false;
};

} // namespace viscera::sim
