#pragma once
/// Haptic device state and commands, named as CRTK names them (measured_cp, measured_cv,
/// servo_cf, jaw/measured_js, jaw/servo_jf). Units SI: metres, radians, seconds, newtons.
/// Frames: poses and twists are in the device's base frame; forces are commanded in that same
/// frame. Timestamps are nanoseconds on the clock that produced the sample.
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <string>

namespace viscera::haptics {

using Vec3 = Eigen::Vector3d;
using Quat = Eigen::Quaterniond;

/// At most two arms per device (a bimanual console has a left and a right master).
constexpr int kMaxArms = 2;
/// Pedal bits of DeviceState::pedals (the bimanual console has five pedals).
enum Pedal : uint32_t {
    kPedalClutch = 1u << 0,  ///< held: the tool stays, the master can be re-centred; no force
    kPedalCamera = 1u << 1,  ///< held: the masters steer the laparoscope (ServoConfig::cameraPedalHolds)
    kPedalDeadman = 1u << 2, ///< must be held for any force to reach a device that has pedals
    kPedalEnergyCut = 1u << 3,
    kPedalEnergyCoag = 1u << 4,
    kPedalMask = 0x1Fu,
};

enum class Hand : uint8_t { Left, Right, Either };
const char* handName(Hand h);

/// Cartesian pose: position (m) and orientation (unit quaternion), device base frame.
struct Pose {
    Vec3 position = Vec3::Zero();
    Quat orientation = Quat::Identity();
};

/// Cartesian twist: linear (m/s) and angular (rad/s) velocity, device base frame.
struct Twist {
    Vec3 linear = Vec3::Zero();
    Vec3 angular = Vec3::Zero();
};

/// Cartesian wrench: force (N) and torque (N·m), device base frame.
struct Wrench {
    Vec3 force = Vec3::Zero();
    Vec3 torque = Vec3::Zero();
};

/// What one arm (master) of a device can do.
struct ArmCapabilities {
    Hand hand = Hand::Either;
    int dof = 7; ///< 3 position + 3 orientation + grip
    bool grip = true;
    double maxForce = 15.0;                     ///< N, magnitude
    double maxTorque = 0.0;                     ///< N·m, magnitude (0: no torque rendering)
    double maxGripForce = 0.0;                  ///< N
    Vec3 workspaceMin = Vec3(-0.4, -0.2, -0.2); ///< m, axis-aligned box in the base frame
    Vec3 workspaceMax = Vec3(0.4, 0.2, 0.2);    ///< m (80 × 40 × 40 cm, [B §4])
    Vec3 workspaceCentre() const { return 0.5 * (workspaceMin + workspaceMax); }
};

struct DeviceCapabilities {
    std::string name; ///< e.g. "console 127.0.0.1:7400"
    int arms = 1;     ///< 1..kMaxArms
    std::array<ArmCapabilities, kMaxArms> arm{};
    int pedals = 0;        ///< number of pedals (0 = none: the deadman rule does not apply)
    bool realtime = false; ///< true when the device runs on wall-clock time (network, keyboard)
};

/// One arm's measured state (CRTK measured_*).
struct ArmState {
    Pose measured_cp;           ///< measured Cartesian position
    Twist measured_cv;          ///< measured Cartesian velocity
    double jaw_measured_js = 0; ///< grip opening angle, rad
    uint32_t buttons = 0;       ///< bit set of the arm's buttons
};

/// A device's measured state at one instant.
struct DeviceState {
    int64_t timestamp_ns = 0; ///< when the sample was taken, device clock
    uint64_t sequence = 0;    ///< increases with every new sample
    bool connected = false;   ///< false while the device does not answer
    uint32_t pedals = 0;      ///< Pedal bits
    std::array<ArmState, kMaxArms> arms{};
};

/// One arm's command (CRTK servo_cf and jaw/servo_jf).
struct ArmCommand {
    Wrench servo_cf;         ///< Cartesian force/torque to render, N and N·m, base frame
    double jaw_servo_jf = 0; ///< grip force, N
};

struct DeviceCommand {
    int64_t timestamp_ns = 0; ///< when the command was computed, servo clock
    uint64_t sequence = 0;
    uint32_t flags = 0; ///< CommandFlag bits (what the safety filter did)
    std::array<ArmCommand, kMaxArms> arms{};
};

/// Bits of DeviceCommand::flags (mirrored in the console protocol).
enum CommandFlag : uint32_t {
    kFlagForceEnabled = 1u << 0, ///< at least one arm may receive a non-zero force
    kFlagSimStale = 1u << 1,
    kFlagDisconnected = 1u << 2,
    kFlagDeadmanOpen = 1u << 3,
    kFlagClutch = 1u << 4,
};

} // namespace viscera::haptics
