#pragma once
/// Number formatting for messages and reports.
#include <string>

namespace viscera::sim {

/// `v` as printf "%.*g" with `significantDigits` significant digits ("0.001", "1e+06", "inf"),
/// except that every NaN prints as "nan" (never "-nan"), so messages compare verbatim on every
/// platform.
std::string formatNumber(double v, int significantDigits = 6);

} // namespace viscera::sim
