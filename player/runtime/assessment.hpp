#pragma once
/// A session measured and judged against its case's assessment [issue 41]: the metrics of
/// sim::metricCatalogue() measured from the session's timeline (one definition each, used by
/// the summary, the report, the plots and the page alike), then per metric pass or fail against
/// its limit and within or outside its expert level, and the verdict.
#include "sim/scene/assessment.hpp"

#include <optional>
#include <string>
#include <vector>

namespace viscera::player {

struct SessionResult;

/// One tool's figures over the session (from the timeline).
struct ToolFigures {
    std::string name, kind, hand;
    double pathM = 0, angularRad = 0;
    double forceMaxN = 0, forceMeanN = 0, overThresholdS = 0, damageNs = 0;
};

/// One metric of the session. value: none when it cannot be measured (the targets were never met
/// for the completion time). With an expert level, `bound` is mean + 2 sd (lower is better) or
/// mean − 2 sd (higher is better).
struct MetricResult {
    std::string name, unit;
    bool lowerIsBetter = true;
    std::optional<double> value;
    std::optional<double> limit;
    bool passed = true; ///< no limit, or the value on the good side of it (an absent value fails a limit)
    std::optional<sim::ExpertLevel> expert;
    double bound = 0;
    std::optional<bool> withinExpert; ///< none without an expert level
};

struct Assessment {
    bool judged = false; ///< the case has an assessment block (a verdict); else figures only
    bool passed = true;  ///< every metric passed (judged cases)
    std::optional<double> completionS;
    std::vector<MetricResult> metrics; ///< catalogue order, the metrics that apply to the case
    std::vector<ToolFigures> tools;
    const MetricResult* find(std::string_view name) const;
    /// Every metric with an expert level is within it (false when none has one).
    bool withinExpertLevel() const;
    /// The verdict's second half: "completion 5.88 s; within the expert level" (each part only
    /// where the case has targets, expert levels).
    std::string verdictDetail() const;
};

/// Measures `r` (its timeline, suture and interaction figures) and judges it against `desc`
/// (none: figures without a verdict). Never throws; a non-finite figure is left out (value none).
Assessment assessSession(const SessionResult& r, const std::optional<sim::AssessmentDesc>& desc);

/// "pass", "FAIL"; a metric line "path_length_m 0.412 m (limit ≤ 0.6) pass, expert ≤ 0.35: outside".
std::string metricLine(const MetricResult& m);
/// A figure with three significant digits, never "-0", "nan" or "inf" ("—" for none).
std::string formatFigure(std::optional<double> v);

} // namespace viscera::player
