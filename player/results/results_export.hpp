#pragma once
/// Every session with its metrics, for a spreadsheet (CSV: one row per metric of a session, the
/// session's columns repeated; a session without metrics has one row with empty metric columns)
/// or for a program (JSON: an array of sessions, each with its metrics).
#include "results/learning_curve.hpp"

#include <string>
#include <vector>

namespace viscera::player {

std::string exportCsv(const std::vector<LearningCurve>& curves);
std::string exportJson(const std::vector<LearningCurve>& curves);

} // namespace viscera::player
