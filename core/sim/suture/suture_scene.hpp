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
#include "sim/suture/suture_sim.hpp"

#include <array>
#include <string>
#include <string_view>

namespace viscera::sim {

struct SutureSceneDesc {
    SutureSettings settings;          ///< fem.youngsModulus / poissonRatio come from the bodies' material
    bool thread = false;              ///< "thread" present: pulls in the trajectory are applied
    bool contact = false;             ///< "contact" present: VF/EE contact between bodies
    std::string trajectoryPath;       ///< file inside the case
    std::string trajectoryText;       ///< its contents, filled by whoever reads the case (not serialized)
    std::array<std::string, 2> gauge; ///< body names; empty = no closure figures
};

/// Read and written by readSutureSection / sutureJson (sim/scene/scene_json.hpp).

} // namespace viscera::sim
