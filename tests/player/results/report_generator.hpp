#pragma once
// Synthetic session reports (schema 5: record + assessment) of trainees over attempts, for the
// results database tests.
#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace viscera::test {

/// The metrics every synthetic report carries: three with an expert level (completion_time_s
/// and path_length_m lower is better, cut_coverage higher is better), one without (force_max_n).
inline const std::vector<std::string> kExpertMetrics{"completion_time_s", "path_length_m", "cut_coverage"};

/// Attempt `attempt` (1-based) of a trainee who improves: every expert-levelled metric within
/// its level from attempt 6 on (so proficient at attempt 7); attempt 1 fails its time limit,
/// attempt 2 its clip accuracy limit.
nlohmann::json improvingReport(const std::string& trainee, int attempt);
/// Attempt `attempt` of a trainee who is never proficient: within the expert level on even
/// attempts only (never two in a row); attempt 3 never meets the task's targets (time null).
nlohmann::json strugglingReport(const std::string& trainee, int attempt);

/// Writes reports 1..n of `trainee` as <dir>/<trainee>-<attempt>.json; returns the paths.
std::vector<std::filesystem::path> writeReports(const std::filesystem::path& dir, const std::string& trainee, int n,
                                                bool improving);

} // namespace viscera::test
