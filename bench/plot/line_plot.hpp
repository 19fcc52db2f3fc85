#pragma once
/// Minimal line-plot writer for benchmark figures: PNG through Qt6 Gui (QImage + QPainter), no
/// display needed (an offscreen QGuiApplication is created when the process has none). Bench
/// tools only; core libraries never link Qt.
#include <optional>
#include <string>
#include <vector>

namespace viscera::bench {

struct PlotSeries {
    std::string label;
    std::vector<double> x, y; ///< same length; points that a log axis cannot show are skipped
    bool markers = false;     ///< draw a dot at every point (for short series such as Newton's)
};

enum class LegendPlacement { OutsideRight, TopLeft, TopRight, BottomLeft, BottomRight };

struct PlotSpec {
    std::string title, xLabel, yLabel;
    bool logX = false, logY = true;
    int width = 1600, height = 900; ///< pixels
    /// Horizontal reference lines (e.g. a target error), drawn dashed and labelled with the value.
    std::vector<double> yMarks;
    /// Axis bounds; each one left empty is taken from the data (and yMarks), widened to whole
    /// decades on a log axis.
    std::optional<double> xMin, xMax, yMin, yMax;
    LegendPlacement legend = LegendPlacement::OutsideRight;
};

/// Renders the series and writes a PNG to `path`. Returns an empty string on success, otherwise
/// what failed ("no plottable point", "cannot write <path>").
std::string writeLinePlotPng(const std::string& path, const PlotSpec& spec, const std::vector<PlotSeries>& series);

} // namespace viscera::bench
