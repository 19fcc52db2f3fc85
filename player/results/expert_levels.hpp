#pragma once
/// Expert levels derived from expert sessions [issue 41]: per metric, the mean and the sample
/// standard deviation of the experts' values over their sessions of one case, as the fragment
/// the studio's Assessment dock imports into the case ({"case_id", "experts", "sessions",
/// "metrics": {"<name>": {"expert": {"mean", "sd"}, "n"}}}).
#include "results/session_record.hpp"

#include <string>
#include <vector>

namespace viscera::player {

struct DerivedLevel {
    std::string name, unit;
    int n = 0; ///< sessions with a value
    double mean = 0, sd = 0;
};

/// Every metric with a value in at least two of `sessions` (catalogue names as the reports give
/// them, in their order). Throws viscera::InputError when fewer than two sessions are given.
std::vector<DerivedLevel> deriveExpertLevels(const std::vector<SessionRecord>& sessions);
/// The fragment the studio imports (JSON text).
std::string expertLevelsJson(const std::string& caseId, const std::vector<std::string>& experts, size_t sessions,
                             const std::vector<DerivedLevel>& levels);

} // namespace viscera::player
