#pragma once
/// Numbers in messages and reports.
#include <cstdio>
#include <string>

namespace viscera::sim {

/// v as printf "%.*g" with `significantDigits` digits ("0.1", "1e+06").
inline std::string formatNumber(double v, int significantDigits = 6) {
    char b[40];
    std::snprintf(b, sizeof b, "%.*g", significantDigits, v);
    return b;
}

} // namespace viscera::sim
