#pragma once
/// A trainee's attempts at one case, numbered, and the attempt at which they became proficient.
///
/// Proficiency: reached at the second of two consecutive attempts (same trainee, same case) that
/// both passed and in which every metric with an expert level was within it.
#include "results/session_record.hpp"

#include <optional>
#include <string>
#include <vector>

namespace viscera::player {

struct Attempt {
    int number = 0; ///< 1-based, in start-time order within trainee + case
    const SessionRecord* session = nullptr;
    int expertMetrics = 0, withinExpert = 0; ///< metrics with an expert level, of them within it
    bool atExpertLevel = false;              ///< passed, and every expert-levelled metric within it
};

struct LearningCurve {
    std::string trainee, caseId;
    std::vector<Attempt> attempts;
    std::optional<int> proficientAt; ///< the attempt number; empty: not yet
    /// "proficient at attempt 7" or "not yet proficient (…why…)".
    std::string verdict() const;
};

/// One curve per trainee + case of `sessions` (which must outlive the curves), in the order
/// trainee, case; the attempts of each in start-time order (then database id).
std::vector<LearningCurve> learningCurves(const std::vector<SessionRecord>& sessions);

} // namespace viscera::player
