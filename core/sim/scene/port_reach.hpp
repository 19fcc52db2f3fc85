#pragma once
/// Can each instrument reach the task's targets through its trocar port? [issue 57 item 1]
///
/// An instrument through a declared port reaches a point when the port allows a pose whose tip
/// lies on it (constrainToPort leaves it where it is): within max_angle_deg of the port's rest
/// axis (port → the tool's rest tip, the first key of its track) and at an insertion within the
/// port's range. Which targets an instrument must reach follows from its kind:
///   energy hook   every cut line of the assessment (sampled every kReachSampleM along it)
///   clip applier  every clip site
///   grasper       none (it holds tissue wherever the trainee chooses; nothing to check)
/// The studio flags an unreachable target before export (a port placed where its instrument
/// cannot do the task), the command line prints the same lines. Pure; no allocation beyond the
/// result; a scene without an assessment, ports or tracks gives no problem.
#include "sim/scene/port.hpp"

#include <optional>
#include <string>
#include <vector>

namespace viscera::sim {

struct SceneDesc;
struct AssessmentDesc;
struct InstrumentDesc;

/// Spacing (m) of the points checked along a cut line (its vertices always are).
inline constexpr double kReachSampleM = 0.002;

struct ReachProblem {
    size_t instrument = 0;     ///< index in scene.interaction->instruments
    std::string target;        ///< "assessment.targets.cut[0]" / "assessment.targets.clip[1]"
    Vec3 point = Vec3::Zero(); ///< the first point of the target the port cannot reach, m
    double distance = 0;       ///< m, from that point to the nearest tip the port allows (∞: not finite)
    std::string message;       ///< one line naming the instrument, the target and why
};

/// A task target an instrument must reach: its field in the scene and the points checked.
struct ReachTarget {
    std::string field;        ///< "assessment.targets.cut[0]"
    std::vector<Vec3> points; ///< m
};
/// The targets of `assessment` an instrument of kind `instrument.kind` must reach (see above).
std::vector<ReachTarget> targetsToReach(const InstrumentDesc& instrument, const AssessmentDesc& assessment);
/// The port frame of `instrument` as the run time makes it (its rest tip: the first key of its
/// track text); none without a declared port or a readable track.
std::optional<PortFrame> instrumentPortFrame(const InstrumentDesc& instrument);

/// Every target of scene.assessment an instrument of scene.interaction must reach and its port
/// cannot (one problem per instrument and target, the first point that fails). `tolerance` (m):
/// how far the nearest allowed tip may lie from a point that still counts as reached.
std::vector<ReachProblem> unreachableTargets(const SceneDesc& scene, double tolerance = 1e-4);

/// Why the port cannot place the tip at `target`, or empty when it can (within `tolerance`, m):
/// "63.2° from the port's axis, beyond max_angle_deg 50" / "0.41 m from the port, outside the
/// insertion range [0.04, 0.26]".
std::string reachRule(const PortFrame& port, const Vec3& target, double tolerance = 1e-4);

} // namespace viscera::sim
