// The servo loop driven tick by tick on a deterministic clock (lockstep), and once on its own
// thread: virtual coupling against the local contact model, stale simulation, clutch,
// disconnect and reconnection, contact-model age (checked by the hand-over audit too), and the trace.
#include "haptics/handover_audit.hpp"
#include "haptics/scripted_device.hpp"
#include "haptics/servo_loop.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

using namespace viscera::haptics;

namespace {

constexpr int64_t kMs = 1'000'000;

/// A one-arm device whose state the test sets directly.
class FakeDevice final : public Device {
public:
    FakeDevice() {
        caps.arms = 1;
        caps.pedals = 5;
        caps.arm[0].maxForce = 15;
    }
    const DeviceCapabilities& capabilities() const override { return caps; }
    void poll(int64_t now, DeviceState& out) override {
        out = state;
        out.timestamp_ns = now;
    }
    void send(const DeviceCommand& c) override {
        last = c;
        ++sent;
    }
    const char* backend() const override { return "fake"; }
    DeviceCapabilities caps;
    DeviceState state;
    DeviceCommand last;
    int sent = 0;
};

/// A flat tissue surface z = 0 under the tool (normal +z), stiffness k, no force at p0.
LocalContactModel wall(int64_t t, int64_t frame, double k = 400) {
    LocalContactModel m;
    m.timestamp_ns = t;
    m.frame = frame;
    m.physicsPeriod_s = 1.0 / 60;
    m.tools[0].active = true;
    m.tools[0].p0 = Vec3::Zero();
    m.tools[0].n = Vec3::UnitZ();
    m.tools[0].f0 = 0;
    m.tools[0].gap = 0;
    m.tools[0].k = k;
    return m;
}

struct Rig {
    FakeDevice dev;
    ManualClock clock{0};
    ServoConfig cfg;
    std::unique_ptr<ServoLoop> servo;
    /// port: the tool through it, its rest tip at the scene start (the origin).
    explicit Rig(double kc = 2000, const viscera::sim::PortDesc* port = nullptr, double damping = 0) {
        cfg.tools[0].enabled = true;
        cfg.tools[0].motionScale = 1.0;
        if (port) {
            cfg.tools[0].throughPort = true;
            cfg.tools[0].port = viscera::sim::makePortFrame(*port, Vec3::Zero(), 1.0);
        }
        cfg.tools[0].couplingStiffness = kc;
        cfg.tools[0].couplingDamping = damping;
        cfg.safety.maxForceRate = 1e6; // the rate rule has its own tests
        dev.state.connected = true;
        dev.state.pedals = kPedalDeadman;
        servo = std::make_unique<ServoLoop>(dev, clock, cfg);
    }
    void tick(double z, int ticks = 1) {
        for (int k = 0; k < ticks; ++k) {
            dev.state.arms[0].measured_cp.position = Vec3(0, 0, z);
            clock.advance(kMs);
            servo->tick(clock.now_ns());
        }
    }
    double force() const { return dev.last.arms[0].servo_cf.force.z(); }
    void tickAt(const Vec3& device) {
        dev.state.arms[0].measured_cp.position = device;
        clock.advance(kMs);
        servo->tick(clock.now_ns());
    }
};

/// A wall x = 0 with its normal +x (tissue on the −x side), stiffness k.
LocalContactModel sideWall(int64_t t, int64_t frame, double k = 400) {
    LocalContactModel m = wall(t, frame, k);
    m.tools[0].n = Vec3::UnitX();
    return m;
}

} // namespace

TEST(ServoLoop, NoForceBeforeTheSimulationPublishes) {
    Rig r;
    r.tick(-0.01, 10);
    EXPECT_EQ(r.dev.sent, 10);
    EXPECT_EQ(r.force(), 0.0);
    EXPECT_EQ(r.servo->stats().safety.simStale, 10u);
}

TEST(ServoLoop, VirtualCouplingInSeriesWithTheLocalModel) {
    Rig r(2000);
    r.tick(0.0); // connects: the tool starts at the scene start (origin)
    r.servo->publishContact(wall(r.clock.now_ns(), 0, 400));
    r.tick(0.01); // above the surface: no force
    EXPECT_EQ(r.force(), 0.0);
    r.servo->publishContact(wall(r.clock.now_ns(), 1, 400));
    r.tick(-0.005); // 5 mm into the surface
    // Series stiffness 400·2000/2400 N/m over 5 mm.
    EXPECT_NEAR(r.force(), 400.0 * 2000 / 2400 * 0.005, 1e-9);
    const ToolPoseState poses = r.servo->toolPoses();
    EXPECT_NEAR(poses.target[0].z(), -0.005, 1e-12);
    EXPECT_GT(poses.proxy[0].z(), -0.005) << "the proxy stays shallower than the master";
    EXPECT_NEAR(poses.proxy[0].z(), -0.005 * 2000 / 2400, 1e-12);
    EXPECT_NEAR(poses.force[0], r.force(), 1e-12);
}

TEST(ServoLoop, StaleSimulationZeroesAndFreshOutputResumes) {
    Rig r;
    r.tick(0.0);
    r.servo->publishContact(wall(r.clock.now_ns(), 0));
    r.tick(-0.004, 50); // 50 ms: exactly the limit
    EXPECT_GT(r.force(), 0.0);
    r.tick(-0.004, 1); // 51 ms old
    EXPECT_EQ(r.force(), 0.0);
    EXPECT_TRUE(r.dev.last.flags & kFlagSimStale);
    r.servo->publishContact(wall(r.clock.now_ns(), 1));
    r.tick(-0.004);
    EXPECT_GT(r.force(), 0.0);
}

TEST(ServoLoop, ClutchHoldsTheToolAndReindexesTheMaster) {
    Rig r;
    r.tick(0.0);
    r.servo->publishContact(wall(r.clock.now_ns(), 0));
    r.tick(0.02);
    r.dev.state.pedals = kPedalDeadman | kPedalClutch;
    r.tick(0.10, 5); // the master moves 8 cm while clutched
    EXPECT_EQ(r.force(), 0.0);
    EXPECT_NEAR(r.servo->toolPoses().target[0].z(), 0.02, 1e-12);
    r.dev.state.pedals = kPedalDeadman;
    r.tick(0.10);
    EXPECT_NEAR(r.servo->toolPoses().target[0].z(), 0.02, 1e-12) << "no jump on release";
    r.servo->publishContact(wall(r.clock.now_ns(), 1));
    r.tick(0.075); // 2.5 cm down from the release point = 5 mm into the surface
    EXPECT_NEAR(r.servo->toolPoses().target[0].z(), -0.005, 1e-12);
    EXPECT_GT(r.force(), 0.0);
}

TEST(ServoLoop, DisconnectZeroesTheForceAndReconnectionResumesWithoutAJump) {
    Rig r;
    r.tick(0.0);
    r.servo->publishContact(wall(r.clock.now_ns(), 0));
    r.tick(-0.004);
    EXPECT_GT(r.force(), 0.0);
    r.dev.state.connected = false;
    r.tick(0.3, 20); // garbage while disconnected
    EXPECT_EQ(r.force(), 0.0);
    EXPECT_TRUE(r.dev.last.flags & kFlagDisconnected);
    EXPECT_NEAR(r.servo->toolPoses().target[0].z(), -0.004, 1e-12);
    r.dev.state.connected = true;
    r.servo->publishContact(wall(r.clock.now_ns(), 1));
    r.tick(0.3); // reconnects at a new master position: the tool stays where it was
    EXPECT_NEAR(r.servo->toolPoses().target[0].z(), -0.004, 1e-12);
    r.tick(0.299); // and follows from there
    EXPECT_NEAR(r.servo->toolPoses().target[0].z(), -0.005, 1e-9);
    EXPECT_GT(r.force(), 0.0);
}

TEST(ServoLoop, ContactModelAgeNeverExceedsOnePhysicsStepInLockstep) {
    // 1 kHz ticks, a physics step published every 1/60 s (16 or 17 ticks).
    ScriptedDevice dev("press");
    ManualClock clock(0);
    ServoConfig cfg;
    cfg.tools[0].enabled = true;
    ServoLoop servo(dev, clock, cfg);
    const double period = 1.0 / 60;
    HandoverAudit audit(period);
    int64_t frame = 0;
    double nextPublish = 0;
    double maxAge = 0;
    int samples = 0;
    for (int tick = 0; tick < 3000; ++tick) {
        const double t = tick * 1e-3;
        clock.set(int64_t(std::llround(t * 1e9)));
        if (t + 1e-12 >= nextPublish) {
            servo.publishContact(wall(clock.now_ns(), frame, 300));
            audit.published(frame++, clock.now_ns(), clock.now_ns());
            nextPublish += period;
        }
        servo.tick(clock.now_ns());
        TraceSample s;
        while (servo.popTrace(s)) {
            ASSERT_GE(s.contactAge_s, 0.0);
            ASSERT_TRUE(s.force.allFinite());
            ASSERT_EQ(s.contactFrame, frame - 1) << "the trace names the model the tick used";
            audit.used(s.t_ns, s.contactFrame);
            maxAge = std::max(maxAge, s.contactAge_s);
            ++samples;
        }
    }
    EXPECT_EQ(samples, 3000);
    EXPECT_LE(maxAge, period + 1e-9);
    const HandoverFigures ho = audit.figures();
    EXPECT_EQ(ho.ticksChecked, 3000u);
    EXPECT_EQ(ho.ticksOnOlderModel, 0u);
    EXPECT_LT(ho.maxAgeOverStep, 1.0);
    EXPECT_EQ(ho.stepsOverPeriod, 0) << "16 and 17 ms steps against 16.67 ms";
    const ServoStats st = servo.stats();
    EXPECT_EQ(st.contactModelsSeen, frame);
    EXPECT_LE(st.contactAge.max_us, period * 1e6 + 1e-3);
    EXPECT_EQ(st.traceDropped, 0u);
}

TEST(ServoLoop, RunsOnItsOwnThreadAgainstTheWallClock) {
    ScriptedDevice dev("circle");
    SteadyClock clock;
    ServoConfig cfg;
    cfg.tools[0].enabled = true;
    cfg.realtimePriority = false;
    ServoLoop servo(dev, clock, cfg);
    servo.start();
    EXPECT_TRUE(servo.running());
    int64_t frame = 0;
    size_t samples = 0;
    for (int k = 0; k < 20; ++k) { // a "physics thread" publishing every ~16 ms
        LocalContactModel m = wall(clock.now_ns(), frame++, 300);
        m.tools[0].p0 = Vec3(0, 0, -0.0175);
        servo.publishContact(m);
        std::this_thread::sleep_for(std::chrono::milliseconds(16));
        TraceSample s;
        while (servo.popTrace(s)) {
            ASSERT_TRUE(s.force.allFinite());
            ASSERT_LE(s.force.norm(), 15.0);
            ++samples;
        }
    }
    servo.stop();
    EXPECT_FALSE(servo.running());
    const ServoStats st = servo.stats();
    EXPECT_GT(st.ticks, 10u);
    EXPECT_GT(samples, 0u);
    EXPECT_GT(st.period.count, 0u);
    EXPECT_GT(st.contactModelsSeen, 1);
    EXPECT_GT(dev.linkStats().sent, 10u);
}

TEST(ServoLoop, PoseHistoryGivesTheLastTickBeforeAnInstant) {
    Rig r;
    // Woken late by 0.3 ms each tick: the poses are stamped at the deadline, the device polled there.
    for (int n = 0; n < 10'000; ++n) {
        r.dev.state.arms[0].measured_cp.position = Vec3(0, 0, 1e-6 * n);
        r.servo->tick(n * kMs + 300'000, n * kMs);
    }
    ToolPoseState p;
    EXPECT_EQ(r.servo->poseBefore(9'999 * kMs + 1, p), PoseLookup::NotYet) << "no tick after the instant yet";
    ASSERT_EQ(r.servo->poseBefore(9'999 * kMs, p), PoseLookup::Found);
    EXPECT_EQ(p.tick, 9'999u);
    EXPECT_EQ(p.timestamp_ns, 9'998 * kMs);
    ASSERT_EQ(r.servo->poseBefore(5'000 * kMs + 1, p), PoseLookup::Found);
    EXPECT_EQ(p.timestamp_ns, 5'000 * kMs);
    EXPECT_DOUBLE_EQ(p.target[0].z(), 1e-6 * 5'000) << "the input of that tick, not the latest";
    // Beyond the history: the oldest ticks are gone.
    const int64_t kept = static_cast<int64_t>(ServoLoop::kPoseHistory);
    EXPECT_EQ(r.servo->poseBefore((10'000 - kept) * kMs, p), PoseLookup::Dropped);
    ASSERT_EQ(r.servo->poseBefore((10'000 - kept + 100) * kMs, p), PoseLookup::Found);
    EXPECT_EQ(p.timestamp_ns, (10'000 - kept + 99) * kMs);

    // Before the first tick the first tick's poses stand; a skipped tick (an overrun) is passed over.
    EXPECT_EQ(r.servo->firstTickNs(), 0) << "the first tick's deadline: the session's time zero";
    Rig q;
    EXPECT_EQ(q.servo->firstTickNs(), INT64_MIN) << "no tick yet";
    q.servo->tick(0, 0);
    q.servo->tick(kMs, kMs);
    q.servo->tick(5 * kMs, 4 * kMs); // ticks at 2 and 3 ms skipped
    ASSERT_EQ(q.servo->poseBefore(-kMs, p), PoseLookup::Found);
    EXPECT_EQ(p.tick, 1u);
    ASSERT_EQ(q.servo->poseBefore(3 * kMs + 500'000, p), PoseLookup::Found);
    EXPECT_EQ(p.timestamp_ns, kMs);
    EXPECT_EQ(q.servo->poseBefore(4 * kMs + 1, p), PoseLookup::NotYet);
}

TEST(ServoLoop, ThroughAPortTheFulcrumInvertsTheHandAndTheForceStillOpposesIt) {
    // A port 10 cm above the tool's rest tip; the master moves 1 cm to +x.
    viscera::sim::PortDesc port;
    port.declared = true;
    port.position = Vec3(0, 0, 0.10);
    port.insertionMin = 0.03;
    port.insertionMax = 0.15;
    port.shaftLength = 0.30;
    for (auto mode : {viscera::sim::PortMode::Laparoscopic, viscera::sim::PortMode::Robotic}) {
        port.mode = mode;
        const bool lap = mode == viscera::sim::PortMode::Laparoscopic;
        Rig r(2000, &port);
        r.tickAt(Vec3::Zero());
        EXPECT_LT(r.servo->toolPoses().target[0].norm(), 1e-12) << "the master's centre holds the rest tip";
        r.tickAt(Vec3(0.01, 0, 0));
        const Vec3 tip = r.servo->toolPoses().target[0];
        // Sideways the tip moves motion_scale (1) per device metre: opposite in laparoscopic mode.
        EXPECT_NEAR(tip.x(), lap ? -0.01 : 0.01, lap ? 5e-4 : 1e-12) << viscera::sim::portModeName(mode);
        // Into a side wall on the side the tip went: the force pushes the hand back.
        const Vec3 hand = lap ? Vec3(0.004, 0, 0) : Vec3(-0.004, 0, 0);
        r.servo->publishContact(sideWall(r.clock.now_ns(), 0));
        r.tickAt(hand);
        const Vec3 f = r.dev.last.arms[0].servo_cf.force;
        EXPECT_LT(f.dot(hand), 0.0) << viscera::sim::portModeName(mode) << ": the force opposes the hand";
        EXPECT_GT(r.servo->toolPoses().force[0], 0.0);
        // Damping resists the approach: the same pose with the hand moving on into the wall pushes
        // back harder (through a laparoscopic port the tip's velocity is the hand's reversed).
        {
            Rig d(2000, &port, 20.0);
            d.tickAt(Vec3::Zero());
            d.servo->publishContact(sideWall(d.clock.now_ns(), 0));
            d.tickAt(hand);
            const double still = d.dev.last.arms[0].servo_cf.force.norm();
            d.dev.state.arms[0].measured_cv.linear = hand.normalized() * 0.05; // 5 cm/s on into the wall
            d.tickAt(hand);
            const double moving = d.dev.last.arms[0].servo_cf.force.norm();
            EXPECT_GT(moving, still + 1e-3) << viscera::sim::portModeName(mode);
        }
        // The master pushed 1 m down (the handle past the port in laparoscopic mode): the insertion
        // stops at its maximum; pulled 1 m up, at its minimum.
        r.servo->publishContact(wall(r.clock.now_ns(), 1, 0));
        for (double z : {-1.0, 1.0}) {
            r.tickAt(Vec3(0, 0, z));
            const Vec3 t = r.servo->toolPoses().target[0];
            ASSERT_TRUE(t.allFinite());
            EXPECT_NEAR((t - port.position).norm(), z < 0 ? port.insertionMax : port.insertionMin, 1e-9)
                << viscera::sim::portModeName(mode) << " z " << z;
            EXPECT_LT(t.z(), port.position.z()) << "the tip stays inside the body";
        }
        // Past a limit nothing is stored: from 1 m past the deepest insertion, 1 cm back draws the
        // tip back at once.
        r.tickAt(Vec3(0, 0, -1.0));
        const double deepest = (r.servo->toolPoses().target[0] - port.position).norm();
        r.tickAt(Vec3(0, 0, -0.99));
        const double back = (r.servo->toolPoses().target[0] - port.position).norm();
        EXPECT_NEAR(deepest - back, 0.01, 1e-3) << viscera::sim::portModeName(mode);
    }
}
