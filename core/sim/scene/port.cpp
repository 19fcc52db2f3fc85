#include "sim/scene/port.hpp"
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace viscera::sim {
namespace {

constexpr double kTiny = 1e-9;
constexpr double kMinLeverOutside = 0.02; ///< m: the handle never comes closer to the port

/// Any unit vector perpendicular to the unit vector a.
Vec3 anyPerpendicular(const Vec3& a) {
    const Vec3 other = std::abs(a.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
    return a.cross(other).normalized();
}

double restInsertion(const PortFrame& port) {
    return std::clamp((port.restTip - port.desc.position).norm(), port.desc.insertionMin, port.desc.insertionMax);
}

} // namespace

std::string restTipError(const PortDesc& desc, const Vec3& tip) {
    const double d = (tip - desc.position).norm();
    if (d >= desc.insertionMin && d <= desc.insertionMax) return {};
    char text[200];
    if (std::isfinite(d))
        std::snprintf(text, sizeof text, "lies %.4g m from its port, outside the port's insertion [%.4g, %.4g]", d,
                      desc.insertionMin, desc.insertionMax);
    else
        std::snprintf(text, sizeof text, "lies beyond the port's insertion [%.4g, %.4g]", desc.insertionMin,
                      desc.insertionMax);
    return text;
}

const char* portModeName(PortMode mode) {
    return mode == PortMode::Robotic ? "robotic" : "laparoscopic";
}

Vec3 handleMove(const PortFrame& port, const Vec3& deviceMove, double motionScale) {
    const Vec3 along = deviceMove.dot(port.axis) * port.axis;
    return motionScale * along + port.handScale * (deviceMove - along);
}

PortFrame makePortFrame(const PortDesc& port, const Vec3& restTip, double motionScale) {
    PortFrame f;
    f.desc = port;
    const Vec3 v = restTip - port.position;
    f.axis = v.allFinite() && v.norm() > kTiny ? Vec3(v.normalized()) : Vec3(-Vec3::UnitZ());
    f.restTip = port.position + f.axis * std::clamp(v.norm(), port.insertionMin, port.insertionMax);
    const double in = restInsertion(f);
    const double out = std::max(port.shaftLength - in, kMinLeverOutside);
    const double lever = std::max(in / out, 0.05);
    f.handScale = (std::isfinite(motionScale) && motionScale > 0 ? motionScale : 1.0) / lever;
    f.restHandle = port.position - f.axis * out;
    return f;
}

PortPose constrainToPort(const PortFrame& port, const Vec3& target) {
    const PortDesc& p = port.desc;
    PortPose out;
    Vec3 v = target - p.position;
    double len = v.norm();
    if (!v.allFinite() || !std::isfinite(len)) {
        v = port.restTip - p.position;
        len = v.norm();
    }
    Vec3 d = len > kTiny ? Vec3(v / len) : port.axis;
    const double maxAngle = p.maxAngleDeg * M_PI / 180.0;
    const double cosAngle = std::clamp(d.dot(port.axis), -1.0, 1.0);
    if (std::acos(cosAngle) > maxAngle) {
        Vec3 perp = d - cosAngle * port.axis;
        perp = perp.norm() > kTiny ? Vec3(perp.normalized()) : anyPerpendicular(port.axis);
        d = std::cos(maxAngle) * port.axis + std::sin(maxAngle) * perp;
        out.angleLimited = true;
        len = std::max(0.0, v.dot(d)); // the target's nearest point on the turned shaft
    }
    out.insertionLimited = len < p.insertionMin || len > p.insertionMax;
    out.insertion = std::clamp(len, p.insertionMin, p.insertionMax);
    out.direction = d;
    out.tip = p.position + d * out.insertion;
    return out;
}

PortPose fulcrumTip(const PortFrame& port, const Vec3& handle) {
    const PortDesc& p = port.desc;
    if (!handle.allFinite()) return constrainToPort(port, port.restTip);
    // A handle at or past the port's level (pushed in to its end) is held just outside it, its
    // sideways offset kept: the shaft fully in, continuous as the handle crosses the level.
    Vec3 h = handle;
    const double level = (p.position - h).dot(port.axis);
    const bool past = level < kMinLeverOutside;
    if (past) h -= (kMinLeverOutside - level) * port.axis;
    const Vec3 u = p.position - h;
    const double outside = u.norm();
    if (outside < kTiny) return constrainToPort(port, port.restTip);
    const Vec3 d = u / outside;
    const double inside = p.shaftLength - outside;
    // A handle pulled back past the shaft's length would put the tip outside: the shaft stops at
    // its shortest insertion, still along the handle's line.
    PortPose pose = constrainToPort(port, p.position + d * std::max(inside, p.insertionMin));
    pose.insertionLimited = pose.insertionLimited || inside < p.insertionMin || past;
    return pose;
}

Vec3 fulcrumHandle(const PortFrame& port, const Vec3& tip) {
    const PortPose pose = constrainToPort(port, tip);
    const double outside = std::max(port.desc.shaftLength - pose.insertion, kMinLeverOutside);
    return port.desc.position - pose.direction * outside;
}

Vec3 handForce(const PortFrame& port, const PortPose& pose, const Vec3& tipForce) {
    if (!tipForce.allFinite()) return Vec3::Zero();
    if (port.desc.mode == PortMode::Robotic) return tipForce;
    const Vec3& d = pose.direction;
    const Vec3 axial = tipForce.dot(d) * d;
    const double outside = std::max(port.desc.shaftLength - pose.insertion, kMinLeverOutside);
    return axial - (pose.insertion / outside) * (tipForce - axial);
}

double shaftDistanceToPort(const Vec3& port, const Vec3& tip, const Vec3& direction, double length) {
    const double n = direction.norm();
    if (!(n > kTiny) || !tip.allFinite() || !port.allFinite()) return INFINITY;
    const Vec3 d = direction / n;
    const double s = std::clamp((tip - port).dot(d), 0.0, std::max(length, 0.0));
    return (tip - s * d - port).norm();
}

double twistAbout(const Eigen::Vector4d& wxyz, const Vec3& axis) {
    if (!wxyz.allFinite() || !(axis.norm() > kTiny)) return 0;
    const double along = wxyz.tail<3>().dot(axis.normalized());
    double a = 2.0 * std::atan2(along, wxyz[0]);
    if (a > M_PI) a -= 2 * M_PI;
    if (a <= -M_PI) a += 2 * M_PI;
    return a;
}

} // namespace viscera::sim
