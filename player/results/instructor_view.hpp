#pragma once
/// The instructor's view: per case, every trainee with their number of attempts, passes, best
/// completion time and whether (at which attempt) they became proficient; as a text table and
/// as a self-contained HTML page.
#include "results/learning_curve.hpp"

#include <optional>
#include <string>
#include <vector>

namespace viscera::player {

struct TraineeSummary {
    std::string caseId, trainee;
    int attempts = 0, passes = 0;
    std::optional<double> bestCompletion_s;
    std::optional<int> proficientAt;
};

/// One row per curve (trainee + case), ordered by case then trainee.
std::vector<TraineeSummary> summarize(const std::vector<LearningCurve>& curves);

/// Text: one block per case, a header line then one aligned line per trainee.
std::string instructorText(const std::vector<TraineeSummary>& rows);
/// The page (no external file).
std::string instructorHtml(const std::vector<TraineeSummary>& rows);

/// The list table: one line per session (attempt number per trainee + case, start time, passed,
/// completion time, proficient so far).
std::string sessionTable(const std::vector<LearningCurve>& curves);

} // namespace viscera::player
