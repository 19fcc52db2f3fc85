#pragma once
/// The report's "assessment" block: its writer and the one reader of its metric entries, side by
/// side (the session plots and the results database read what the player wrote). Header for
/// .cpp files only (nlohmann::json).
#include "runtime/assessment.hpp"
#include "runtime/report_reader.hpp"

#include <nlohmann/json.hpp>

#include <string>

namespace viscera::player {

/// {"judged", "passed" (null unjudged), "completion_time_s", "within_expert_level",
///  "metrics": [{name, unit, value, better, limit, passed, expert {mean, sd, bound}, within_expert}],
///  "tools": [{name, kind, hand, path_m, angular_path_rad, force_max_n, force_mean_n,
///             force_over_threshold_s, tissue_damage_ns}]}; a non-finite figure is null.
nlohmann::json assessmentJson(const Assessment& a);
/// One entry of "metrics" (`field` names it in messages: "assessment.metrics[3]"). Throws
/// viscera::InputError "<origin>: <field>.<key>: <rule>".
MetricResult readMetricJson(const ReportReader& rd, const nlohmann::json& metric, const std::string& field);

} // namespace viscera::player
