#pragma once
// Counts the pixels of an image that have the learning curves' expert-band colour.
#include "results/progress_page.hpp"

#include <QColor>
#include <QImage>
#include <QString>

#include <cstdlib>
#include <string>

namespace viscera::test {

/// Pixels within `tolerance` (per channel) of player::kExpertBandRgb; -1: the image did not load.
inline long bandPixels(const std::string& png, int tolerance = 4) {
    QImage img(QString::fromStdString(png));
    if (img.isNull()) return -1;
    long n = 0;
    for (int y = 0; y < img.height(); ++y)
        for (int x = 0; x < img.width(); ++x) {
            const QColor c = img.pixelColor(x, y);
            if (std::abs(c.red() - player::kExpertBandRgb[0]) <= tolerance &&
                std::abs(c.green() - player::kExpertBandRgb[1]) <= tolerance &&
                std::abs(c.blue() - player::kExpertBandRgb[2]) <= tolerance)
                ++n;
        }
    return n;
}

} // namespace viscera::test
