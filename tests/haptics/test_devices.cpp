// Device specs, the replay backend on a deterministic clock, scripted motions, keyboard input.
#include "haptics/device_spec.hpp"
#include "haptics/keyboard_device.hpp"
#include "haptics/replay_device.hpp"
#include "haptics/scripted_device.hpp"
#include "sim/util/error.hpp"

#include "haptics/link_auth.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

using namespace viscera::haptics;
using ::testing::HasSubstr;

namespace {
constexpr int64_t kMs = 1'000'000;

std::string specError(const std::string& spec) {
    try {
        openDevice(parseDeviceSpec(spec));
    } catch (const viscera::InputError& e) {
        return e.what();
    }
    return "(accepted)";
}
} // namespace

TEST(DeviceSpec, ParsesEveryBackendAndRejectsBadSpecs) {
    EXPECT_EQ(parseDeviceSpec("keyboard").kind, DeviceSpec::Kind::Keyboard);
    EXPECT_EQ(parseDeviceSpec("scripted:press").argument, "press");
    EXPECT_EQ(parseDeviceSpec("console:127.0.0.1:7400").kind, DeviceSpec::Kind::Console);
    EXPECT_EQ(parseDeviceSpec("replay:/tmp/x.csv").argument, "/tmp/x.csv");
    EXPECT_THAT(specError("joystick:1"), HasSubstr("--device 'joystick:1': unknown device backend"));
    EXPECT_THAT(specError("replay:"), HasSubstr("replay needs an argument"));
    EXPECT_THAT(specError("console:nohost"), HasSubstr("must be host:port"));
    EXPECT_THAT(specError("console:1.2.3.4:99999"), HasSubstr("port '99999' must be an integer"));
    EXPECT_THAT(specError("console:my.host:7400"), HasSubstr("must be an IPv4 address"));
    EXPECT_THAT(specError("scripted:dance"), HasSubstr("unknown script (known: idle, press"));
    EXPECT_THAT(specError("replay:/nonexistent/t.csv"), HasSubstr("/nonexistent/t.csv"));
    EXPECT_NE(openDevice(parseDeviceSpec("scripted:circle")), nullptr);
    // The console needs the pairing key file: without one, or with a malformed one, one line.
    const DeviceSpec console = parseDeviceSpec("console:127.0.0.1:9");
    auto openError = [&](const DeviceOpenOptions& o) {
        try {
            openDevice(console, o);
        } catch (const viscera::InputError& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    EXPECT_THAT(openError({}), HasSubstr("the console link needs the pairing key shared with the console: "
                                         "--pairing-key FILE"));
    const std::string dir = ::testing::TempDir();
    const std::string good = dir + "/viscera-test-pairing.key", bad = dir + "/viscera-test-bad.key";
    std::ofstream(good) << formatPairingKey(randomKey());
    std::ofstream(bad) << std::string(63, 'a') << "g\n";
    DeviceOpenOptions o;
    o.pairingKeyFile = good;
    std::filesystem::permissions(good, std::filesystem::perms::others_read, std::filesystem::perm_options::add);
    EXPECT_NE(openError(o).find(good + ": the pairing key is open to other users (mode "), std::string::npos)
        << openError(o);
    for (const std::string& f : {good, bad})
        std::filesystem::permissions(f, std::filesystem::perms::owner_read | std::filesystem::perms::owner_write);
    o.pairingKeyFile = bad;
    EXPECT_EQ(openError(o), bad + ": a pairing key is 64 hexadecimal digits (character 64 is not one)");
    o.pairingKeyFile = good;
    EXPECT_STREQ(openDevice(console, o)->backend(), "console");
    EXPECT_EQ(loadPairingKey(good).size(), kLinkKeySize);
}

TEST(ReplayDevice, PlaysOnTheCallersClockRepeatably) {
    Trajectory t;
    for (int k = 0; k <= 100; ++k) {
        TrajectorySample s;
        s.t = 0.01 * k;
        s.pose.position = Vec3(0, 0, -0.001 * k);
        s.pedals = kPedalDeadman;
        t.add(0, s);
    }
    auto run = [&] {
        ReplayDevice dev(t);
        std::vector<double> z;
        DeviceState st;
        for (int64_t ms = 5000; ms <= 6000; ms += 50) { // time zero is the first poll
            dev.poll(ms * kMs, st);
            z.push_back(st.arms[0].measured_cp.position.z());
            EXPECT_TRUE(st.connected);
        }
        return z;
    };
    const auto a = run(), b = run();
    EXPECT_EQ(a, b);
    EXPECT_DOUBLE_EQ(a[0], 0.0);
    EXPECT_NEAR(a[10], -0.05, 1e-12);
    EXPECT_NEAR(a.back(), -0.1, 1e-12);
}

TEST(ScriptedDevice, PressDescendsHoldsAndRises) {
    ScriptedDevice dev("press");
    EXPECT_EQ(dev.capabilities().arms, 1);
    DeviceState st;
    dev.poll(0, st);
    EXPECT_NEAR(st.arms[0].measured_cp.position.z(), 0.0, 1e-12);
    EXPECT_TRUE(st.pedals & kPedalDeadman);
    dev.poll(2500 * kMs, st);
    EXPECT_NEAR(st.arms[0].measured_cp.position.z(), -0.09, 1e-12);
    dev.poll(1000 * kMs, st);
    EXPECT_LT(st.arms[0].measured_cv.linear.z(), 0);
    dev.poll(5000 * kMs, st);
    EXPECT_NEAR(st.arms[0].measured_cp.position.z(), 0.0, 1e-12);
    ScriptedDevice clutch("clutch");
    clutch.poll(0, st);
    clutch.poll(4000 * kMs, st);
    EXPECT_TRUE(st.pedals & kPedalClutch);
    ScriptedDevice two("bimanual");
    EXPECT_EQ(two.capabilities().arms, 2);
}

TEST(KeyboardDevice, KeysAndMouseMoveTheMasterInsideTheWorkspace) {
    KeyboardDevice dev(0.1, 1e-3);
    DeviceState st;
    dev.poll(0, st);
    dev.setKey(KeyboardDevice::KeyRight, true);
    dev.poll(100 * kMs, st);
    EXPECT_NEAR(st.arms[0].measured_cp.position.x(), 0.01, 1e-12);
    dev.setKey(KeyboardDevice::KeyRight, false);
    dev.setKey(KeyboardDevice::KeyClutch, true);
    dev.addMouse(10, -20, 0);
    dev.poll(200 * kMs, st);
    EXPECT_NEAR(st.arms[0].measured_cp.position.x(), 0.02, 1e-9);
    EXPECT_NEAR(st.arms[0].measured_cp.position.y(), 0.02, 1e-9);
    EXPECT_TRUE(st.pedals & kPedalClutch);
    dev.addMouse(1e6, 0, 0); // far outside: clamped to the workspace
    dev.poll(300 * kMs, st);
    EXPECT_NEAR(st.arms[0].measured_cp.position.x(), dev.capabilities().arm[0].workspaceMax.x(), 1e-12);
    EXPECT_EQ(dev.capabilities().arm[0].maxForce, 0.0);
    // the grip, cut and button keys: jaws closed, the energy pedal, the arm's button, while held
    EXPECT_TRUE(dev.capabilities().arm[0].grip);
    EXPECT_DOUBLE_EQ(st.arms[0].jaw_measured_js, KeyboardDevice::kOpenGrip);
    dev.setKey(KeyboardDevice::KeyGrip, true);
    dev.setKey(KeyboardDevice::KeyCut, true);
    dev.setKey(KeyboardDevice::KeyButton, true);
    dev.poll(400 * kMs, st);
    EXPECT_DOUBLE_EQ(st.arms[0].jaw_measured_js, 0.0);
    EXPECT_TRUE(st.pedals & kPedalEnergyCut);
    EXPECT_EQ(st.arms[0].buttons, 1u);
    dev.setKey(KeyboardDevice::KeyGrip, false);
    dev.setKey(KeyboardDevice::KeyCut, false);
    dev.setKey(KeyboardDevice::KeyButton, false);
    dev.poll(500 * kMs, st);
    EXPECT_DOUBLE_EQ(st.arms[0].jaw_measured_js, KeyboardDevice::kOpenGrip);
    EXPECT_FALSE(st.pedals & kPedalEnergyCut);
    EXPECT_EQ(st.arms[0].buttons, 0u);
}
