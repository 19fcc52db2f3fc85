#pragma once
/// Numbers as the studio shows them: sim::formatNumber (shortest form with `digits` significant
/// digits, the same text the command line and reports print), as a QString.
#include "sim/util/format.hpp"

#include <QObject>
#include <QString>

#include <cmath>
#include <optional>

namespace viscera::studio {

inline QString numberText(double v, int digits = 6) {
    return QString::fromStdString(sim::formatNumber(v, digits));
}

/// A number typed into a field: finite, else nullopt and `why` = "<field>: '<text>' is not a
/// finite number" (the one rule of every typed value before the model's own rules).
inline std::optional<double> parseNumberText(const QString& text, const QString& field, QString& why) {
    bool ok = false;
    const double v = text.trimmed().toDouble(&ok);
    if (!ok || !std::isfinite(v)) {
        why = QObject::tr("%1: '%2' is not a finite number").arg(field, text);
        return std::nullopt;
    }
    return v;
}

} // namespace viscera::studio
