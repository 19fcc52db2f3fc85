#pragma once
/// The trainee's session as the results database keeps it: the "record" and "assessment" of a
/// session report (schema 5 or newer), and nothing else of the report.
///
/// readSessionRecord() is the one reader of those fields; it refuses a malformed report with one
/// line "<origin>: <field>: <rule>" (viscera::InputError), e.g.
/// "r.json: assessment.metrics[2].better: must be \"lower\" or \"higher\"".
#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace viscera::player {

/// The newest report schema this program reads; the first with a trainee record is 5.
inline constexpr int kResultsNewestSchema = 5;
inline constexpr int kResultsOldestSchema = 5;

/// The expert level of a metric: `bound` = mean + 2 sd when lower is better, mean − 2 sd when
/// higher is better (in the metric's unit).
struct ExpertLevel {
    double mean = 0, sd = 0, bound = 0;
};

/// One assessed metric of a session, in SI units (`unit` says which).
struct MetricRecord {
    std::string name, unit;
    std::optional<double> value; ///< empty: the session could not measure it
    bool lowerIsBetter = true;   ///< "better": "lower" | "higher"
    std::optional<double> limit; ///< empty: no pass/fail limit
    bool passed = true;
    std::optional<ExpertLevel> expert; ///< empty: no expert level for this metric
    std::optional<bool> withinExpert;  ///< empty when there is no expert level
};

struct SessionRecord {
    int64_t id = 0;     ///< the database's session id; 0 when not stored
    std::string origin; ///< the report file, in messages
    std::string trainee, startedUtc, playerVersion, caseId, caseVersion, packageSha256;
    std::string reportSha256; ///< sha256 of the report's bytes (the database's duplicate key)
    bool passed = false;
    std::optional<double> completionTime_s; ///< empty: the task's targets were never met
    std::vector<MetricRecord> metrics;
};

/// Reads the record and the assessment of a parsed report. Throws viscera::InputError
/// "<origin>: <field>: <rule>". `reportSha256` is left empty.
SessionRecord readSessionRecord(const nlohmann::json& report, const std::string& origin);

/// The same from a file (size-capped read, JSON syntax errors named with their position); fills
/// reportSha256 from the file's bytes.
SessionRecord readSessionRecordFile(const std::filesystem::path& reportPath);

/// Lowercase hex sha256 of `bytes`.
std::string sha256Hex(const std::string& bytes);

} // namespace viscera::player
