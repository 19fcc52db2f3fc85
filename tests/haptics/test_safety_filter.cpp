// Every rule of the safety filter, alone and together: non-finite input, disconnect, stale
// simulation, deadman, clamping to device and case maxima, dF/dt.
#include "haptics/safety_filter.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

using namespace viscera::haptics;

namespace {

constexpr int64_t kMs = 1'000'000;

DeviceCapabilities console(double maxForce = 15.0, int pedals = 5) {
    DeviceCapabilities c;
    c.arms = 2;
    for (auto& a : c.arm) {
        a.maxForce = maxForce;
        a.maxTorque = 0.5;
        a.maxGripForce = 2.0;
    }
    c.pedals = pedals;
    return c;
}

DeviceCommand force(const Vec3& f0, const Vec3& f1 = Vec3::Zero()) {
    DeviceCommand c;
    c.arms[0].servo_cf.force = f0;
    c.arms[1].servo_cf.force = f1;
    return c;
}

/// Input that passes every zeroing rule at time t (ms).
SafetyInput ok(int64_t t_ms) {
    SafetyInput in;
    in.now_ns = t_ms * kMs;
    in.simTimestamp_ns = in.now_ns - 5 * kMs;
    in.deviceConnected = true;
    in.pedals = kPedalDeadman;
    return in;
}

bool allFinite(const DeviceCommand& c) {
    for (const auto& a : c.arms)
        if (!a.servo_cf.force.allFinite() || !a.servo_cf.torque.allFinite() || !std::isfinite(a.jaw_servo_jf))
            return false;
    return true;
}

bool isZero(const DeviceCommand& c) {
    for (const auto& a : c.arms)
        if (a.servo_cf.force.squaredNorm() != 0 || a.servo_cf.torque.squaredNorm() != 0 || a.jaw_servo_jf != 0)
            return false;
    return true;
}

/// Ramps the filter up to a steady output of `f` on arm 0.
void settle(SafetyFilter& s, const Vec3& f, int64_t& t) {
    DeviceCommand out;
    for (int k = 0; k < 200; ++k)
        s.apply(ok(++t), force(f), out);
}

} // namespace

TEST(SafetyFilter, PassesAForceWithinAllLimitsAfterTheRamp) {
    SafetyFilter s(console(), SafetyLimits{});
    int64_t t = 0;
    settle(s, Vec3(1, 2, 3), t);
    DeviceCommand out;
    EXPECT_EQ(s.apply(ok(++t), force(Vec3(1, 2, 3)), out), 0u);
    EXPECT_TRUE(out.arms[0].servo_cf.force.isApprox(Vec3(1, 2, 3)));
    EXPECT_TRUE(out.flags & kFlagForceEnabled);
}

TEST(SafetyFilter, ClampsToTheCaseMaximumKeepingTheDirection) {
    SafetyLimits lim;
    lim.maxForce = 5.0;
    SafetyFilter s(console(15.0), lim);
    EXPECT_DOUBLE_EQ(s.effectiveMaxForce(0), 5.0);
    int64_t t = 0;
    settle(s, Vec3(0, 0, 100), t);
    DeviceCommand out;
    const uint32_t rules = s.apply(ok(++t), force(Vec3(0, 0, 100)), out);
    EXPECT_TRUE(rules & kRuleClamped);
    EXPECT_NEAR(out.arms[0].servo_cf.force.norm(), 5.0, 1e-12);
    EXPECT_NEAR(out.arms[0].servo_cf.force.normalized().z(), 1.0, 1e-12);
}

TEST(SafetyFilter, ClampsToTheDeviceMaximumWhenItIsLower) {
    SafetyLimits lim; // case default 15 N
    lim.maxTorque = 1.0;
    lim.maxGripForce = 5.0;
    SafetyFilter s(console(3.0), lim);
    EXPECT_DOUBLE_EQ(s.effectiveMaxForce(1), 3.0);
    int64_t t = 0;
    DeviceCommand out;
    for (int k = 0; k < 200; ++k)
        s.apply(ok(++t), force(Vec3::Zero(), Vec3(-40, 0, 0)), out);
    EXPECT_NEAR(out.arms[1].servo_cf.force.norm(), 3.0, 1e-12);
    // Torque and grip force are clamped too.
    DeviceCommand in = force(Vec3::Zero());
    in.arms[0].servo_cf.torque = Vec3(0, 0, 9);
    in.arms[0].jaw_servo_jf = 50;
    EXPECT_TRUE(s.apply(ok(++t), in, out) & kRuleClamped);
    EXPECT_NEAR(out.arms[0].servo_cf.torque.norm(), 0.5, 1e-12);
    EXPECT_DOUBLE_EQ(out.arms[0].jaw_servo_jf, 2.0);
}

TEST(SafetyFilter, LimitsTheRateOfChangeOfForce) {
    SafetyLimits lim;
    lim.maxForceRate = 1000.0; // N/s: 1 N per 1 ms tick
    SafetyFilter s(console(), lim);
    DeviceCommand out;
    int64_t t = 0;
    s.apply(ok(++t), force(Vec3::Zero()), out);
    double prev = 0;
    for (int k = 0; k < 20; ++k) {
        const uint32_t rules = s.apply(ok(++t), force(Vec3(10, 0, 0)), out);
        const double f = out.arms[0].servo_cf.force.x();
        EXPECT_LE(f - prev, 1.0 + 1e-9) << "tick " << k;
        if (k < 9) {
            EXPECT_TRUE(rules & kRuleRateLimited);
        }
        prev = f;
    }
    EXPECT_NEAR(prev, 10.0, 1e-9);
    // Down as well as up.
    s.apply(ok(++t), force(Vec3(0, 0, 0)), out);
    EXPECT_NEAR(out.arms[0].servo_cf.force.x(), 9.0, 1e-9);
    // A long gap between ticks does not allow a jump larger than 10 ms of ramp.
    t += 1000;
    s.apply(ok(t), force(Vec3(-15, 0, 0)), out);
    EXPECT_NEAR(out.arms[0].servo_cf.force.x(), -1.0, 1e-9);
}

TEST(SafetyFilter, NonFiniteInputGivesZeroNeverNaN) {
    const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
    for (int which = 0; which < 4; ++which) {
        SafetyFilter s(console(), SafetyLimits{});
        int64_t t = 0;
        settle(s, Vec3(4, 0, 0), t);
        DeviceCommand in = force(Vec3(4, 0, 0), Vec3(1, 1, 1));
        if (which == 0) in.arms[0].servo_cf.force.y() = nan;
        if (which == 1) in.arms[1].servo_cf.force.x() = inf;
        if (which == 2) in.arms[0].servo_cf.torque.z() = nan;
        if (which == 3) in.arms[1].jaw_servo_jf = -inf;
        DeviceCommand out;
        const uint32_t rules = s.apply(ok(++t), in, out);
        EXPECT_TRUE(rules & kRuleNonFinite) << which;
        EXPECT_TRUE(allFinite(out)) << which;
        EXPECT_TRUE(isZero(out)) << which;
        EXPECT_FALSE(out.flags & kFlagForceEnabled);
        // Recovery ramps from zero: no spike back to 4 N.
        s.apply(ok(++t), force(Vec3(4, 0, 0)), out);
        EXPECT_LE(out.arms[0].servo_cf.force.norm(), 1.0 + 1e-9);
    }
    EXPECT_EQ(SafetyFilter(console(), SafetyLimits{}).counts().nonFinite, 0u);
}

TEST(SafetyFilter, DisconnectZeroesAndReconnectionRamps) {
    SafetyFilter s(console(), SafetyLimits{});
    int64_t t = 0;
    settle(s, Vec3(0, 6, 0), t);
    DeviceCommand out;
    SafetyInput in = ok(++t);
    in.deviceConnected = false;
    EXPECT_TRUE(s.apply(in, force(Vec3(0, 6, 0)), out) & kRuleDisconnected);
    EXPECT_TRUE(isZero(out));
    EXPECT_TRUE(out.flags & kFlagDisconnected);
    s.apply(ok(++t), force(Vec3(0, 6, 0)), out);
    EXPECT_NEAR(out.arms[0].servo_cf.force.y(), 1.0, 1e-9);
    EXPECT_EQ(s.counts().disconnected, 1u);
}

TEST(SafetyFilter, StaleSimulationZeroesTheForce) {
    SafetyLimits lim;
    lim.maxSimAge_ns = 50 * kMs;
    SafetyFilter s(console(), lim);
    int64_t t = 0;
    settle(s, Vec3(2, 0, 0), t);
    DeviceCommand out;
    SafetyInput in = ok(++t);
    in.simTimestamp_ns = in.now_ns - 50 * kMs; // exactly the limit: still fresh
    EXPECT_FALSE(s.apply(in, force(Vec3(2, 0, 0)), out) & kRuleSimStale);
    EXPECT_GT(out.arms[0].servo_cf.force.norm(), 0);
    in = ok(++t);
    in.simTimestamp_ns = in.now_ns - 50 * kMs - 1;
    EXPECT_TRUE(s.apply(in, force(Vec3(2, 0, 0)), out) & kRuleSimStale);
    EXPECT_TRUE(isZero(out));
    EXPECT_TRUE(out.flags & kFlagSimStale);
    // A simulation that never published (timestamp far in the past) is stale too.
    in.simTimestamp_ns = INT64_MIN / 2;
    EXPECT_TRUE(s.apply(in, force(Vec3(2, 0, 0)), out) & kRuleSimStale);
}

TEST(SafetyFilter, DeadmanPedalMustBeHeldOnDevicesWithPedals) {
    SafetyFilter s(console(), SafetyLimits{});
    EXPECT_TRUE(s.requiresDeadman());
    int64_t t = 0;
    settle(s, Vec3(2, 0, 0), t);
    DeviceCommand out;
    SafetyInput in = ok(++t);
    in.pedals = kPedalClutch | kPedalCamera; // everything but the deadman
    EXPECT_TRUE(s.apply(in, force(Vec3(2, 0, 0)), out) & kRuleDeadman);
    EXPECT_TRUE(isZero(out));
    EXPECT_TRUE(out.flags & kFlagDeadmanOpen);
    // A device without pedals (replay of a pedal-less recording, keyboard) is not gated.
    SafetyFilter noPedals(console(15.0, 0), SafetyLimits{});
    EXPECT_FALSE(noPedals.requiresDeadman());
    in.pedals = 0;
    EXPECT_FALSE(noPedals.apply(in, force(Vec3(0.5, 0, 0)), out) & kRuleDeadman);
    EXPECT_GT(out.arms[0].servo_cf.force.norm(), 0);
}

TEST(SafetyFilter, AllZeroingRulesTogetherStillGiveZero) {
    SafetyFilter s(console(), SafetyLimits{});
    DeviceCommand out;
    SafetyInput in;
    in.now_ns = 1000 * kMs;
    in.simTimestamp_ns = 0;
    in.deviceConnected = false;
    in.pedals = 0;
    DeviceCommand bad = force(Vec3(NAN, 1e30, -1e30), Vec3(1e300, 0, 0));
    const uint32_t rules = s.apply(in, bad, out);
    EXPECT_EQ(rules & (kRuleNonFinite | kRuleDisconnected | kRuleSimStale | kRuleDeadman),
              uint32_t(kRuleNonFinite | kRuleDisconnected | kRuleSimStale | kRuleDeadman));
    EXPECT_TRUE(isZero(out));
    EXPECT_TRUE(allFinite(out));
}

TEST(SafetyFilter, HugeFiniteInputsNeverExceedTheMaximum) {
    SafetyFilter s(console(), SafetyLimits{});
    DeviceCommand out;
    int64_t t = 0;
    for (int k = 0; k < 5000; ++k) {
        const double sign = (k % 7 < 3) ? 1 : -1;
        s.apply(ok(++t), force(Vec3(sign * 1e12, 3e11, -1e9), Vec3(0, sign * 1e200, 0)), out);
        ASSERT_TRUE(allFinite(out));
        ASSERT_LE(out.arms[0].servo_cf.force.norm(), 15.0 + 1e-9);
        ASSERT_LE(out.arms[1].servo_cf.force.norm(), 15.0 + 1e-9);
    }
}

TEST(SafetyFilter, BadLimitsFallBackToZeroForce) {
    SafetyLimits lim;
    lim.maxForce = NAN;
    SafetyFilter s(console(), lim);
    EXPECT_EQ(s.effectiveMaxForce(0), 0.0);
    DeviceCommand out;
    int64_t t = 0;
    settle(s, Vec3(1, 0, 0), t);
    s.apply(ok(++t), force(Vec3(1, 0, 0)), out);
    EXPECT_TRUE(isZero(out));
}
