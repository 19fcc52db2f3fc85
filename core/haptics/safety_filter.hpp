#pragma once
/// The safety filter between the servo loop and every device. Per tick, in this order:
///   1. a non-finite value anywhere in the desired command  → every output is zero;
///   2. the device is not answering (disconnected)           → zero;
///   3. the simulation output is older than maxSimAge        → zero;
///   4. the device has a deadman pedal and it is not held    → zero;
///   5. each arm's force is clamped to min(case maximum, device maximum) (direction kept),
///      torque and grip force likewise;
///   6. each arm's force may change by at most maxForceRate · dt from the previous output
///      (dt = time since the previous tick, at most 10 ms), so a jump in the input — a
///      reconnection, a stale simulation coming back, a flood of packets — ramps instead of
///      kicking. Rules 1–4 drop to zero at once (zero is always safe) and restart the ramp
///      from zero.
/// apply() is allocation- and lock-free (the servo thread calls it every tick); the output never
/// holds NaN or infinity and never exceeds the limits.
#include "haptics/types.hpp"

#include <atomic>
#include <cstdint>

namespace viscera::haptics {

struct SafetyLimits {
    double maxForce = 15.0;            ///< N, the case's maximum (the device's own maximum also applies)
    double maxTorque = 0.0;            ///< N·m
    double maxGripForce = 0.0;         ///< N
    double maxForceRate = 1000.0;      ///< N/s per arm
    int64_t maxSimAge_ns = 50'000'000; ///< simulation output older than this zeroes the force
};

/// Bits returned by SafetyFilter::apply (what the filter did on this tick).
enum SafetyRule : uint32_t {
    kRuleNonFinite = 1u << 0,
    kRuleDisconnected = 1u << 1,
    kRuleSimStale = 1u << 2,
    kRuleDeadman = 1u << 3,
    kRuleClamped = 1u << 4,
    kRuleRateLimited = 1u << 5,
};

struct SafetyInput {
    int64_t now_ns = 0;          ///< servo clock
    int64_t simTimestamp_ns = 0; ///< when the simulation output behind `desired` was produced
    bool deviceConnected = true;
    uint32_t pedals = 0; ///< Pedal bits from the device
};

struct SafetyCounts {
    uint64_t ticks = 0, nonFinite = 0, disconnected = 0, simStale = 0, deadman = 0, clamped = 0, rateLimited = 0;
};

class SafetyFilter {
public:
    SafetyFilter(const DeviceCapabilities& device, const SafetyLimits& limits);
    /// Writes the safe command into `out` (timestamp, sequence and flags copied from desired;
    /// flags gain kFlagDisconnected / kFlagSimStale / kFlagDeadmanOpen / kFlagForceEnabled).
    /// Returns the SafetyRule bits that acted.
    uint32_t apply(const SafetyInput& in, const DeviceCommand& desired, DeviceCommand& out);
    /// Forget the previous output (the next force ramps from zero).
    void reset();
    SafetyCounts counts() const;
    double effectiveMaxForce(int arm) const { return m_maxForce[arm]; }
    bool requiresDeadman() const { return m_deadman; }

private:
    SafetyLimits m_limits;
    std::array<double, kMaxArms> m_maxForce{}, m_maxTorque{}, m_maxGrip{};
    int m_arms = 1;
    bool m_deadman = false;
    bool m_havePrev = false;
    int64_t m_prev_ns = 0;
    std::array<Vec3, kMaxArms> m_prevForce{Vec3::Zero(), Vec3::Zero()};
    std::atomic<uint64_t> m_ticks{0}, m_nonFinite{0}, m_disconnected{0}, m_stale{0}, m_deadmanOpen{0}, m_clamped{0},
        m_rate{0};
};

} // namespace viscera::haptics
