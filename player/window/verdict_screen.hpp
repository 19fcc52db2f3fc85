#pragma once
/// The trainee window's end-of-session screen [issue 41]: the verdict (pass or fail), the
/// completion time, whether the session was within the expert level and one row per metric with
/// its value, limit and result, as the summary and the report give them (player/runtime/assessment).
#include "runtime/assessment.hpp"

#include <QPainter>

#include <string>

namespace viscera::player {

/// Paints the screen over the whole of `size` (the case's title on top, the keys to leave below).
void paintVerdictScreen(QPainter& p, const QSize& size, const Assessment& a, const std::string& title);

} // namespace viscera::player
