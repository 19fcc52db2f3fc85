#include "sim/util/format.hpp"

#include <cmath>
#include <cstdio>

namespace viscera::sim {

std::string formatNumber(double v, int significantDigits) {
    if (std::isnan(v)) return "nan";
    char buf[32];
    const int n = std::snprintf(buf, sizeof buf, "%.*g", significantDigits, v);
    if (n < 0) return {};
    if (static_cast<size_t>(n) < sizeof buf) return std::string(buf, static_cast<size_t>(n));
    std::string out(static_cast<size_t>(n), '\0'); // a long precision: print again, full length
    std::snprintf(out.data(), out.size() + 1, "%.*g", significantDigits, v);
    return out;
}

} // namespace viscera::sim
