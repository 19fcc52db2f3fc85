#pragma once
/// Numbers as the studio shows them: sim::formatNumber (shortest form with `digits` significant
/// digits, the same text the command line and reports print), as a QString.
#include "sim/util/format.hpp"

#include <QString>

namespace viscera::studio {

inline QString numberText(double v, int digits = 6) {
    return QString::fromStdString(sim::formatNumber(v, digits));
}

} // namespace viscera::studio
