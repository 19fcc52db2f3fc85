#pragma once
/// The "suture" section of scene.json (solver "fem"): needle, thread, contact, the recorded needle
/// trajectory file inside the case and the pair of bodies whose closure is reported.
///
/// "suture": {
///   "needle": {"shape": "semicircle" | "straight", "radius": 0.0042, "length": 0.02,
///              "handle": 0.0066, "puncture_force_n": 0.008},
///   "thread": {"length": 1.0, "slack": 0.002, "stabilization": 0.0002,
///              "max_strain_per_step": 0.05},                          optional → feature "thread"
///   "contact": {"thickness": 1e-6, "rounds": 3, "per_round": 48, "max": 256},  optional → "contact"
///   "trajectory": "tools/needle.traj",     text format of anastomosis.hpp (one pose + pull per frame)
///   "gauge": ["wide", "narrow"]            optional: closure gap/penetration between two bodies
/// }
/// Units SI (metres, newtons). Parsing is strict; errors name the origin, the field and the rule.
#include "sim/scene/device_mapping.hpp"
#include "sim/suture/suture_sim.hpp"

#include <array>
#include <string>
#include <string_view>

namespace viscera::sim {

/// suture "device" (optional): a haptic master drives the needle holder when the player runs with
/// a device. {"hand": "right", "motion_scale": 0.25, "force_scale": 1.0, "max_force_n": 15,
/// "pull_scale": 0.1}: the master moves the needle's centre from where the recorded trajectory
/// starts (motion_scale scene metres per device metre) and turns it about that centre by the
/// master's orientation taken in the needle's own frame (a roll about the master's z turns the
/// needle about its axis and so drives it along its curve); the other
/// master's lift above its workspace centre pulls the thread (pull = pull_scale × lift, never
/// given back). The tissue's force on the needle goes back to the needle hand, the thread
/// tension to the other.
struct NeedleDeviceDesc : DeviceMapping {
    NeedleDeviceDesc() { hand = "right"; }
    double pullScale = 0.1; ///< thread metres per device metre of lift
};

struct SutureSceneDesc {
    SutureSettings settings;          ///< fem.youngsModulus / poissonRatio come from the bodies' material
    bool thread = false;              ///< "thread" present: pulls in the trajectory are applied
    bool contact = false;             ///< "contact" present: VF/EE contact between bodies
    std::string trajectoryPath;       ///< file inside the case
    std::string trajectoryText;       ///< its contents, filled by whoever reads the case (not serialized)
    std::array<std::string, 2> gauge; ///< body names; empty = no closure figures
    NeedleDeviceDesc device;
};

/// Read and written by readSutureSection / sutureJson (sim/scene/scene_json.hpp).

} // namespace viscera::sim
