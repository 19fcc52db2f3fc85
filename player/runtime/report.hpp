#pragma once
/// The session report (JSON) of the DESIGN.md command-line contract, and the one-screen summary.
#include "runtime/session.hpp"

#include <nlohmann/json.hpp>

#include <string>

namespace viscera::player {

/// The report's "schemaVersion": raised when a field changes meaning or goes away (new fields
/// keep it). 2: tool names and per-tool forces, warnings, the largest node displacement is over
/// the run (final_node_displacement_m is the end). 3: the console link is authenticated
/// (haptics.link: rejected_checksum gave way to rejected_auth, with rejected_jump, rejected_peer,
/// stale_welcomes and handshakes). 5: "record" and "assessment"; the metrics' forces are the
/// tissue's (device forces as device_max_force_n, device_mean_force_n; max_force_n, mean_force_n
/// and damage_events went away).
constexpr int kReportSchemaVersion = 5;
nlohmann::json reportJson(const SessionResult& result);
/// The force and pose trace (--trace): one row per servo tick and driven arm.
/// Columns: t_s, arm, device_x/y/z (m, device frame), tool_x/y/z (m, scene), force_x/y/z (N,
/// device frame, after the safety filter), force_n, desired_n (before the filter), grip_rad,
/// pedals, connected, safety_rules (SafetyRule bits), contact_age_ms, contact_frame (the physics
/// frame of the contact model the tick used).
std::string traceCsv(const SessionResult& result);
/// A short human-readable summary: the session's figures, then one line per metric and the
/// verdict (assessmentSummary).
std::string summaryText(const SessionResult& result);
/// "metric        <metricLine>" per metric, then "verdict       PASS|FAIL (failed metrics);
/// completion <s> s; within|not within the expert level" (or "none" without an assessment).
std::string assessmentSummary(const Assessment& assessment);
/// The verdict alone, as that summary's last line has it: "PASS; completion 5.88 s; within the
/// expert level", "FAIL (clips_on_target, cut_coverage); ..." or "none (the case has no assessment)".
std::string verdictText(const Assessment& assessment);
/// One line: who signed the package (or that no trusted publisher did) and its SHA-256 and size.
std::string packageSummary(const vcase::Provenance& package);

struct StepTimeStats {
    double mean = 0, p50 = 0, p99 = 0, max = 0; ///< ms
};
StepTimeStats stepTimeStats(const std::vector<sim::FrameRecord>& frames);

/// Physics against real time over a session: the real-time factor (realTimeFactor()) of the mean
/// and of the p99 step, and the frames whose step took longer than the frame time step.
struct RealTimeFigures {
    double factorMean = 0, factorP99 = 0;
    size_t framesOver = 0;
    bool slower() const { return factorMean > 0 && factorMean < 1; } ///< physics slower than real time
};
RealTimeFigures realTimeFigures(const SessionResult& r);

} // namespace viscera::player
