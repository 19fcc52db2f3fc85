#pragma once
/// Session plots [issue 18]: PNG charts of a session report and one self-contained HTML page
/// (the PNGs embedded) for the trainee and the instructor.
///
/// Both `viscera-player run … --plots DIR` and `viscera-player plot report.json -o DIR` go
/// through the report: the run writes its report JSON in memory and plots that, so the two give
/// the same pictures. readPlotInput() is the one reader of what the plots use from a report;
/// it refuses a malformed report with one line naming the file, the field and the rule.
///
/// Drawn with QtGui (QImage + QPainter, no window, no display: an offscreen QGuiApplication is
/// made when none exists).
#include "runtime/assessment.hpp"

#include <nlohmann/json.hpp>

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace viscera::player {

/// What the plots draw, read from a report. A value the report gives as null (a non-finite
/// figure of a failed session) is kept as NaN and drawn as a gap, never as a number.
struct PlotInput {
    std::string origin; ///< the report's file name, in messages
    std::string caseId, caseVersion, title;
    double frameDt_s = 0;
    struct Frame {
        double stepMs = 0, energyJ = 0, maxDisplacementM = 0;
    };
    std::vector<Frame> frames;
    struct Tool {
        std::string name, kind;
        std::vector<std::array<double, 3>> tip; ///< m
        std::vector<double> forceN;
        double pathM = 0, maxForceN = 0; ///< from metrics when the report has them
    };
    std::vector<double> t_s; ///< timeline sample times
    int strideFrames = 1;
    std::vector<Tool> tools;
    struct Event {
        double t_s = 0;
        std::string kind, tool;
        int count = 1;
    };
    std::vector<Event> events;
    bool hasTimeline = false; ///< reports before the timeline was added have none
    struct Accuracy {
        int frame = 0;
        std::string solver;
        std::vector<double> timeMs, relError;
    };
    std::vector<Accuracy> accuracy;
    // Headline figures for the page.
    double simTime_s = 0, wallTime_s = 0, realTimeFactor = 0, stepMsMean = 0, stepMsP99 = 0;
    double maxDeviceForceN = 0, caseMaxForceN = 0; ///< haptics; 0: no device
    std::string device;                            ///< the device spec; empty: none
    int punctures = 0, clips = 0, cutEdges = 0, grasps = 0;
    bool allFinite = true;
    std::vector<std::string> errors, warnings;
    /// The report's "assessment" (schema 5): the metrics and the verdict, as the summary gives them.
    bool hasAssessment = false;
    Assessment assessment;
    std::string trainee, startedUtc; ///< the report's "record"
};

/// Reads what the plots need from a parsed report; `origin` names it in messages. Throws
/// viscera::InputError "<origin>: <field>: <rule>" (e.g. "r.json: frames[3].step_ms: must be a
/// number", "r.json: schemaVersion: 7 is newer than this player reads (3)").
PlotInput readPlotInput(const nlohmann::json& report, const std::string& origin);
/// The same from a file (size-capped read, JSON syntax errors named with their position).
PlotInput readPlotInputFile(const std::filesystem::path& reportPath);

struct PlotFiles {
    std::vector<std::filesystem::path> images; ///< in page order
    std::filesystem::path page;                ///< session.html
};

/// Writes the charts and the page into `dir` (created when missing; every file atomically):
/// step_time.png, forces.png, tool_paths.png, events.png, stability.png, accuracy.png (only
/// when the report has sampled solver error) and session.html. Charts without data (no tool,
/// no event) are still written, saying so, so a page always has the same sections. Throws
/// viscera::InputError naming the path when a file cannot be written.
PlotFiles writeSessionPlots(const PlotInput& in, const std::filesystem::path& dir);

} // namespace viscera::player
