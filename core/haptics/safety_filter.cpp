#include "haptics/safety_filter.hpp"

#include <algorithm>
#include <cmath>

namespace viscera::haptics {
namespace {

bool finite(const DeviceCommand& c, int arms) {
    for (int a = 0; a < arms; ++a) {
        const ArmCommand& x = c.arms[a];
        if (!x.servo_cf.force.allFinite() || !x.servo_cf.torque.allFinite() || !std::isfinite(x.jaw_servo_jf))
            return false;
    }
    return true;
}

/// Clamps |v| to max (max ≥ 0); true when it clamped.
bool clampNorm(Vec3& v, double max) {
    const double n = v.norm();
    if (n <= max) return false;
    v *= max / n;
    return true;
}

double sane(double x) {
    return std::isfinite(x) && x > 0 ? x : 0.0;
}

} // namespace

SafetyFilter::SafetyFilter(const DeviceCapabilities& device, const SafetyLimits& limits) : m_limits(limits) {
    m_arms = std::clamp(device.arms, 1, kMaxArms);
    for (int a = 0; a < kMaxArms; ++a) {
        m_maxForce[a] = std::min(sane(limits.maxForce), sane(device.arm[a].maxForce));
        m_maxTorque[a] = std::min(sane(limits.maxTorque), sane(device.arm[a].maxTorque));
        m_maxGrip[a] = std::min(sane(limits.maxGripForce), sane(device.arm[a].maxGripForce));
    }
    m_limits.maxForceRate = sane(limits.maxForceRate);
    m_deadman = device.pedals >= 3; // the deadman is pedal 2 (kPedalDeadman)
}

void SafetyFilter::reset() {
    m_havePrev = false;
    for (auto& f : m_prevForce)
        f.setZero();
}

uint32_t SafetyFilter::apply(const SafetyInput& in, const DeviceCommand& desired, DeviceCommand& out) {
    uint32_t rules = 0;
    out.timestamp_ns = desired.timestamp_ns;
    out.sequence = desired.sequence;
    out.flags = desired.flags & ~(kFlagForceEnabled | kFlagSimStale | kFlagDisconnected | kFlagDeadmanOpen);
    for (auto& a : out.arms)
        a = ArmCommand{};
    const double dt = m_havePrev ? std::clamp(1e-9 * double(in.now_ns - m_prev_ns), 0.0, 0.010) : 0.001;
    m_havePrev = true;
    m_prev_ns = in.now_ns;
    m_ticks.fetch_add(1, std::memory_order_relaxed);

    if (!finite(desired, m_arms)) rules |= kRuleNonFinite;
    if (!in.deviceConnected) rules |= kRuleDisconnected, out.flags |= kFlagDisconnected;
    const int64_t age = in.now_ns - in.simTimestamp_ns;
    if (age > m_limits.maxSimAge_ns || age < -m_limits.maxSimAge_ns) rules |= kRuleSimStale, out.flags |= kFlagSimStale;
    if (m_deadman && !(in.pedals & kPedalDeadman)) rules |= kRuleDeadman, out.flags |= kFlagDeadmanOpen;
    if (rules) {
        for (auto& f : m_prevForce)
            f.setZero();
        if (rules & kRuleNonFinite) m_nonFinite.fetch_add(1, std::memory_order_relaxed);
        if (rules & kRuleDisconnected) m_disconnected.fetch_add(1, std::memory_order_relaxed);
        if (rules & kRuleSimStale) m_stale.fetch_add(1, std::memory_order_relaxed);
        if (rules & kRuleDeadman) m_deadmanOpen.fetch_add(1, std::memory_order_relaxed);
        return rules;
    }
    const double maxStep = m_limits.maxForceRate * dt;
    for (int a = 0; a < m_arms; ++a) {
        const ArmCommand& d = desired.arms[a];
        ArmCommand& o = out.arms[a];
        Vec3 f = d.servo_cf.force;
        if (clampNorm(f, m_maxForce[a])) rules |= kRuleClamped;
        Vec3 step = f - m_prevForce[a];
        if (clampNorm(step, maxStep)) rules |= kRuleRateLimited;
        f = m_prevForce[a] + step;
        clampNorm(f, m_maxForce[a]); // rounding
        o.servo_cf.force = f;
        m_prevForce[a] = f;
        Vec3 t = d.servo_cf.torque;
        if (clampNorm(t, m_maxTorque[a])) rules |= kRuleClamped;
        o.servo_cf.torque = t;
        o.jaw_servo_jf = std::clamp(d.jaw_servo_jf, -m_maxGrip[a], m_maxGrip[a]);
        if (o.jaw_servo_jf != d.jaw_servo_jf) rules |= kRuleClamped;
    }
    out.flags |= kFlagForceEnabled;
    if (rules & kRuleClamped) m_clamped.fetch_add(1, std::memory_order_relaxed);
    if (rules & kRuleRateLimited) m_rate.fetch_add(1, std::memory_order_relaxed);
    return rules;
}

SafetyCounts SafetyFilter::counts() const {
    auto r = [](const std::atomic<uint64_t>& a) { return a.load(std::memory_order_relaxed); };
    return {r(m_ticks), r(m_nonFinite), r(m_disconnected), r(m_stale), r(m_deadmanOpen), r(m_clamped), r(m_rate)};
}

} // namespace viscera::haptics
