#include "sim/scene/laparoscope.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

namespace viscera::sim {

ScopePose scopePose(const LaparoscopeDesc& desc, const PortFrame& port, const Vec3& target, double roll) {
    const PortPose p = constrainToPort(port, target);
    ScopePose s;
    s.tip = p.tip;
    s.shaft = p.direction;
    s.insertion = p.insertion;
    s.atLimit = p.insertionLimited || p.angleLimited;
    s.roll = std::isfinite(roll) ? roll : 0.0;
    // The optic's "down" at roll 0: the scene's −z across the rest axis (any perpendicular when
    // that is vertical), carried to the shaft by the smallest turn from the axis (the shaft stays
    // within 89° of it, so the image never flips), then turned by the roll about the shaft.
    Vec3 down = -Vec3::UnitZ() - (-Vec3::UnitZ()).dot(port.axis) * port.axis;
    if (down.norm() < 1e-6) down = port.axis.unitOrthogonal();
    down = Eigen::Quaterniond::FromTwoVectors(port.axis, s.shaft) * down.normalized();
    down = Eigen::AngleAxisd(s.roll, s.shaft) * (down - down.dot(s.shaft) * s.shaft).normalized();
    const double a = desc.opticDeg * M_PI / 180.0;
    s.view = (std::cos(a) * s.shaft + std::sin(a) * down).normalized();
    // The image's up: away from the optic's down, perpendicular to the view.
    Vec3 up = -down - (-down).dot(s.view) * s.view;
    s.up = up.norm() > 1e-9 ? Vec3(up.normalized()) : s.view.unitOrthogonal();
    return s;
}

Laparoscope::Laparoscope(const LaparoscopeDesc& desc)
    : m_desc(desc), m_port(makePortFrame(desc.port, desc.tip, desc.motionScale)) {
    m_pose = scopePose(m_desc, m_port, desc.tip, 0.0);
    m_grabTip = m_pose.tip;
}

void Laparoscope::grab() {
    m_grabTip = m_pose.tip;
    m_grabRoll = m_pose.roll;
}

void Laparoscope::steer(const Vec3& deviceMove, double twist) {
    if (!deviceMove.allFinite() || !std::isfinite(twist)) return;
    const Vec3 before = m_pose.tip;
    m_pose = scopePose(m_desc, m_port, m_grabTip + m_desc.motionScale * deviceMove, m_grabRoll + twist);
    m_path += (m_pose.tip - before).norm();
}

} // namespace viscera::sim
