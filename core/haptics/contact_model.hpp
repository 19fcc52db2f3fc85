#pragma once
/// The local contact model: what the physics thread hands the servo loop after every step, so
/// the 1 kHz loop can compute forces between two (slow) physics steps [A §7.3.3: "the geometry
/// needs to be rendered to the haptic device ... at the rate of 1000 Hz"].
///
/// Per tool, a first-order model around the tool centre p0 the physics step used: the contact
/// normal n (unit, pointing from the tissue to the tool), the normal force f0 ≥ 0 the step
/// measured (from the contact multipliers), the gap ≥ 0 to the nearest tissue node when there
/// was no contact, and a local stiffness k (N/m). At a tool centre x, with s = (x − p0)·n:
///     f(x) = max(0, f0 − k (s + gap))   along n.
/// The servo loop couples the device to a tool proxy through a virtual spring (kc, N/m) in
/// series with this model (see ServoLoop), so the proxy never enters the model's surface deeper
/// than the force allows and the rendered stiffness is at most k·kc/(k + kc).
#include "haptics/types.hpp"

#include <algorithm>
#include <cstdint>

namespace viscera::haptics {

struct ToolContactModel {
    bool active = false;    ///< the physics has this tool
    Vec3 p0 = Vec3::Zero(); ///< m, scene frame: tool centre used by the step
    Vec3 n = Vec3::UnitZ(); ///< unit, scene frame
    double f0 = 0;          ///< N
    double gap = 1e9;       ///< m
    double k = 0;           ///< N/m
    double forceAt(const Vec3& x) const {
        if (!active) return 0;
        return std::max(0.0, f0 - k * ((x - p0).dot(n) + gap));
    }
};

struct LocalContactModel {
    int64_t timestamp_ns = 0;   ///< servo clock, when the physics published it
    int64_t frame = -1;         ///< physics frame that produced it (-1: none yet)
    double physicsPeriod_s = 0; ///< nominal time between physics steps
    std::array<ToolContactModel, kMaxArms> tools{};
};

/// What the servo loop hands the physics thread: where each tool (proxy) is.
struct ToolPoseState {
    int64_t timestamp_ns = 0; ///< servo clock: the deadline of the tick that wrote them
    uint64_t tick = 0;
    bool connected = false;
    uint32_t pedals = 0;
    std::array<Vec3, kMaxArms> proxy{Vec3::Zero(), Vec3::Zero()};  ///< m, scene: simulated tool centre
    std::array<Vec3, kMaxArms> target{Vec3::Zero(), Vec3::Zero()}; ///< m, scene: where the master points
    std::array<Quat, kMaxArms> orientation{Quat::Identity(), Quat::Identity()};
    std::array<Vec3, kMaxArms> device{Vec3::Zero(), Vec3::Zero()}; ///< m, device frame: every arm's master
    std::array<double, kMaxArms> grip{0, 0};                       ///< rad
    std::array<uint32_t, kMaxArms> buttons{0, 0};                  ///< the arm's button bits
    std::array<double, kMaxArms> force{0, 0};                      ///< N, magnitude sent to the device (after safety)
    uint32_t safetyRules = 0;
};

} // namespace viscera::haptics
