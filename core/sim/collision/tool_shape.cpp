#include "sim/collision/tool_shape.hpp"

#include "sim/collision/distance.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace viscera::sim {

double signedDistance(const Capsule& c, const Vec3& p) {
    const double t = closestParameterOnSegment(p, c.a, c.b);
    return (p - (c.a + t * (c.b - c.a))).norm() - c.radius;
}

AxisPoint closestAxisPoint(const Capsule& c, const Vec3& p) {
    AxisPoint r;
    const double t = closestParameterOnSegment(p, c.a, c.b);
    r.onAxis = c.a + t * (c.b - c.a);
    const Vec3 d = p - r.onAxis;
    r.distance = d.norm();
    if (r.distance > 1e-15) {
        r.direction = d / r.distance;
    } else {
        const Vec3 axis = c.b - c.a;
        Vec3 u = axis.squaredNorm() > 0 ? axis.unitOrthogonal() : Vec3::UnitZ();
        r.direction = u;
    }
    return r;
}

namespace {
void checkCapsule(const Capsule& c, size_t i, const std::string& where) {
    if (!(c.radius > 0) || !std::isfinite(c.radius) || !c.a.allFinite() || !c.b.allFinite())
        throw std::invalid_argument(where + ": part " + std::to_string(i) +
                                    " needs finite end points and a radius > 0");
}
} // namespace

ToolShape ToolShape::fromCapsules(std::vector<Capsule> parts, const std::string& name) {
    const std::string where = "sim::ToolShape::fromCapsules()";
    if (parts.empty()) throw std::invalid_argument(where + ": a tool needs at least one part");
    for (size_t i = 0; i < parts.size(); ++i)
        checkCapsule(parts[i], i, where);
    ToolShape t;
    t.m_name = name;
    t.m_local = std::move(parts);
    t.refresh();
    return t;
}

ToolShape ToolShape::sphere(double radius) {
    if (!(radius > 0) || !std::isfinite(radius))
        throw std::invalid_argument("sim::ToolShape::sphere(): radius must be > 0, got " + std::to_string(radius));
    return fromCapsules({Capsule{Vec3::Zero(), Vec3::Zero(), radius}}, "sphere");
}

ToolShape ToolShape::capsule(double halfLength, double radius) {
    if (!(radius > 0) || !(halfLength >= 0) || !std::isfinite(radius) || !std::isfinite(halfLength))
        throw std::invalid_argument("sim::ToolShape::capsule(): need radius > 0 and halfLength >= 0");
    return fromCapsules({Capsule{Vec3(-halfLength, 0, 0), Vec3(halfLength, 0, 0), radius}}, "capsule");
}

ToolShape ToolShape::jaws(double length, double radius, double opening) {
    if (!(radius > 0) || !(length > 0) || !std::isfinite(radius) || !std::isfinite(length))
        throw std::invalid_argument("sim::ToolShape::jaws(): need length > 0 and radius > 0");
    if (!(opening >= 0 && opening < M_PI))
        throw std::invalid_argument("sim::ToolShape::jaws(): opening must be in [0, pi) rad, got " +
                                    std::to_string(opening));
    ToolShape t = fromCapsules(
        {Capsule{Vec3::Zero(), Vec3(length, 0, 0), radius}, Capsule{Vec3::Zero(), Vec3(length, 0, 0), radius}}, "jaws");
    t.m_isJaws = true;
    t.m_jawLength = length;
    t.m_jawRadius = radius;
    t.setOpening(opening);
    return t;
}

void ToolShape::setOpening(double opening) {
    if (!m_isJaws || !std::isfinite(opening)) return;
    const double half = 0.5 * std::clamp(opening, 0.0, M_PI - 1e-9);
    // Jaw k rotates about the tool y axis by ±half; tips at length·(cos, 0, ∓sin).
    m_local[0].b = m_jawLength * Vec3(std::cos(half), 0, -std::sin(half));
    m_local[1].b = m_jawLength * Vec3(std::cos(half), 0, std::sin(half));
    refresh();
}

void ToolShape::setPose(const Pose& pose) {
    if (!pose.matrix().allFinite()) return;
    m_pose = pose;
    refresh();
}

void ToolShape::refresh() {
    m_world.resize(m_local.size());
    for (size_t i = 0; i < m_local.size(); ++i) {
        m_world[i].a = m_pose * m_local[i].a;
        m_world[i].b = m_pose * m_local[i].b;
        m_world[i].radius = m_local[i].radius;
    }
}

double ToolShape::signedDistance(const Vec3& p) const {
    double d = 1e300;
    for (const Capsule& c : m_world)
        d = std::min(d, sim::signedDistance(c, p));
    return d;
}

std::array<Vec3, 2> ToolShape::bounds(double margin) const {
    Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
    for (const Capsule& c : m_world) {
        const Vec3 r = Vec3::Constant(c.radius + margin);
        lo = lo.cwiseMin(c.a.cwiseMin(c.b) - r);
        hi = hi.cwiseMax(c.a.cwiseMax(c.b) + r);
    }
    return {lo, hi};
}

ToolShape::Pose interpolatePose(const ToolShape::Pose& a, const ToolShape::Pose& b, double s) {
    const Eigen::Quaterniond qa(a.rotation()), qb(b.rotation());
    ToolShape::Pose p = ToolShape::Pose::Identity();
    p.linear() = qa.slerp(s, qb).toRotationMatrix();
    p.translation() = (1 - s) * a.translation() + s * b.translation();
    return p;
}

} // namespace viscera::sim
