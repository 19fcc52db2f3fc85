#pragma once
/// Learning-curve charts of one trainee on one case: per metric with an expert level, the value
/// against the attempt number over the expert band (mean ± sd shaded, the bound as a dashed
/// line), passed attempts as filled green dots, failed ones as red crosses; and one
/// self-contained HTML page with the charts embedded (data: URIs).
///
/// Drawn with QtGui (QImage + QPainter, offscreen, no display).
#include "results/learning_curve.hpp"

#include <filesystem>
#include <string>
#include <vector>

namespace viscera::player {

/// The band's fill colour (RGB), opaque: what a test looks for in the pixels.
inline constexpr int kExpertBandRgb[3] = {188, 226, 198};

struct ProgressFiles {
    std::vector<std::filesystem::path> images; ///< <metric>.png, in the report's metric order
    std::filesystem::path page;                ///< progress.html
};

/// File name of a metric's chart: the name with every character outside [A-Za-z0-9_.-] as '_',
/// then ".png".
std::string progressImageName(const std::string& metric);

/// Writes the charts and progress.html into `dir` (checked writable first, created when
/// missing; every file atomically). Throws viscera::InputError naming the path on failure.
ProgressFiles writeProgress(const LearningCurve& curve, const std::filesystem::path& dir);

} // namespace viscera::player
