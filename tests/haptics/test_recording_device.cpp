// The recording device: a session's device kept as a trajectory that replays what it did.
#include "haptics/recording_device.hpp"
#include "haptics/replay_device.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace viscera::haptics;

namespace {
constexpr int64_t kMs = 1'000'000;

/// Two arms: arm 0 moves along x and closes its grip; arm 1 presses button 1 at 0.3035 s (between
/// two 10 ms samples) and the cut pedal at 0.5 s.
Trajectory source() {
    Trajectory t;
    TrajectorySample a;
    a.grip = 1.0;
    a.pedals = kPedalDeadman;
    t.add(0, a);
    a.t = 1.0;
    a.pose.position = Vec3(0.1, 0, -0.02);
    a.grip = 0.05;
    t.add(0, a);
    TrajectorySample b;
    b.pedals = kPedalDeadman;
    t.add(1, b);
    b.t = 0.3035;
    b.buttons = 1;
    t.add(1, b);
    b.t = 0.5;
    b.pedals = kPedalDeadman | kPedalEnergyCut;
    t.add(1, b);
    b.t = 1.0;
    b.pose.position = Vec3(0, 0.05, 0);
    t.add(1, b);
    return t;
}

/// Polls `dev` every millisecond from `start_ns` for `ms` ticks.
void run(Device& dev, int64_t start_ns, int ms) {
    DeviceState s;
    for (int k = 0; k < ms; ++k)
        dev.poll(start_ns + k * kMs, s);
}
} // namespace

TEST(RecordingDevice, ReplaysWhatTheDeviceDidWithItsPressesOnTheirTicks) {
    ReplayDevice live(source());
    RecordingDevice rec(live);
    EXPECT_STREQ(rec.backend(), "replay");
    run(rec, 5'000 * kMs, 1201); // servo time 5 s .. 6.2 s: the recording starts at zero
    const Trajectory kept = rec.trajectory();
    ASSERT_EQ(kept.arms(), 2);
    EXPECT_NEAR(kept.duration(), 1.2, 1e-9);
    // Every 10 ms plus the changes: about 121 samples per arm, not one per tick.
    EXPECT_GT(kept.samples(0).size(), 115u);
    EXPECT_LT(kept.samples(1).size(), 135u);
    // The press lands on the first tick at or after it (0.304 s), not on the next 10 ms sample.
    bool pressSeen = false;
    for (const TrajectorySample& s : kept.samples(1))
        if (s.buttons == 1 && !pressSeen) {
            pressSeen = true;
            EXPECT_NEAR(s.t, 0.304, 1e-9);
        }
    EXPECT_TRUE(pressSeen);
    // The kept trajectory replays the live one: pose, grip, buttons and pedals at any instant.
    ReplayDevice original(source()), replayed(kept);
    DeviceState x, y;
    original.poll(0, x), replayed.poll(0, y);
    for (int k = 0; k <= 1200; k += 7) {
        original.poll(k * kMs, x);
        replayed.poll(k * kMs, y);
        for (int a = 0; a < 2; ++a) {
            EXPECT_LT((x.arms[a].measured_cp.position - y.arms[a].measured_cp.position).norm(), 1e-6) << k << " ms";
            EXPECT_NEAR(x.arms[a].jaw_measured_js, y.arms[a].jaw_measured_js, 1e-6) << k << " ms";
            EXPECT_EQ(x.arms[a].buttons, y.arms[a].buttons) << k << " ms";
        }
        EXPECT_EQ(x.pedals, y.pedals) << k << " ms";
    }
    // Saved and read back: the same samples.
    const Trajectory back = Trajectory::parse(kept.format(), "kept.csv");
    ASSERT_EQ(back.samples(1).size(), kept.samples(1).size());
    EXPECT_NEAR(back.samples(1).back().pose.position.y(), 0.05, 1e-9);
}

TEST(RecordingDevice, StopsRecordingWhenFullAndTheDeviceGoesOn) {
    ReplayDevice live(source());
    RecordingDevice rec(live, 0.1, 0.01); // room for 1.25 × 0.1 s of two arms and 16 rows
    run(rec, 0, 1000);
    EXPECT_TRUE(rec.full());
    EXPECT_GT(rec.recordedSeconds(), 0.09);
    EXPECT_LT(rec.recordedSeconds(), 0.25); // a quarter more rows than asked for (room for changes), plus 16
    DeviceState s;
    rec.poll(1000 * kMs, s); // still the live device's state
    EXPECT_NEAR(s.arms[0].measured_cp.position.x(), 0.1, 1e-9);
    const Trajectory kept = rec.trajectory();
    EXPECT_NEAR(kept.duration(), rec.recordedSeconds(), 1e-12);
}

TEST(RecordingDevice, NothingPolledIsAnEmptyTrajectory) {
    ReplayDevice live(source());
    RecordingDevice rec(live);
    EXPECT_EQ(rec.trajectory().arms(), 0);
    EXPECT_EQ(rec.samples(), 0u);
    EXPECT_FALSE(rec.full());
}

/// A device whose state the test sets.
struct SetDevice final : LocalDevice {
    DeviceCapabilities caps;
    DeviceState state;
    const DeviceCapabilities& capabilities() const override { return caps; }
    void poll(int64_t, DeviceState& out) override { out = state; }
    const char* backend() const override { return "set"; }
};

TEST(RecordingDevice, AbsurdSizesAreMadeSaneAndTwoPollsOnOneInstantKeepTheLater) {
    SetDevice dev;
    RecordingDevice nan(dev, std::nan(""), std::nan("")), negative(dev, -5, 1e9);
    DeviceState s;
    nan.poll(0, s);
    negative.poll(0, s);
    EXPECT_EQ(nan.samples(), 1u) << "one arm, the first poll";
    EXPECT_EQ(negative.samples(), 1u) << "a tiny buffer still takes the first poll";
    RecordingDevice rec(dev);
    rec.poll(0, s);
    rec.poll(10 * kMs, s); // a 10 ms sample
    dev.state.arms[0].buttons = 1;
    rec.poll(10 * kMs, s); // the same instant again, now pressed: a change, recorded
    EXPECT_EQ(rec.samples(), 3u);
    const Trajectory t = rec.trajectory();
    ASSERT_EQ(t.samples(0).size(), 2u) << "one sample per instant";
    EXPECT_NEAR(t.samples(0).back().t, 0.010, 1e-12);
    EXPECT_EQ(t.samples(0).back().buttons, 1u) << "the later poll's press is kept";
}
