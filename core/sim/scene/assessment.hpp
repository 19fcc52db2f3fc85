#pragma once
/// A case's assessment: the task's targets, a limit per metric and the expert level per metric
/// [issue 41]. Read and written by the one scene reader (scene_json.hpp: readAssessment,
/// writeAssessment) for the case's scene.json and the studio's project.json alike; evaluated
/// over a session by the player (player/runtime/assessment.hpp).
///
/// scene.json:
///   "assessment": {
///     "targets": {
///       "cut":  [{"line": [[x,y,z], ...], "radius": 0.005, "coverage": 0.5}],
///       "clip": [{"position": [x,y,z], "tolerance": 0.008, "count": 2}],
///       "suture": {"plane": {"point": [x,y,z], "normal": [x,y,z]}, "bites": 2,
///                  "depth": [0.001, 0.006], "spacing": [0.001, 0.01], "max_gap": 0.0005},
///       "vessel": {"body": "vessel", "margin": 0.0015}
///     },
///     "force_threshold_n": 1.0,
///     "reference_path_m": 0.25,
///     "metrics": {"completion_time_s": {"limit": 12, "expert": {"mean": 6, "sd": 1}}, ...}
///   }
///   cut      a marked line (≥ 2 points, m, scene) to open: met when `coverage` (0, 1] of its
///            length has a cut within `radius` (m) of it; edges cut farther away count outside
///   clip     a vessel site: met when `count` clips lie within `tolerance` (m) of `position`
///   suture   the wound's plane between the two edges; a bite is a pass through the wall on one
///            side (two punctures) followed by one on the other, its depth the nearest puncture's
///            distance from the plane; met when `bites` bites lie within `depth`, successive bites
///            within `spacing` (m; or as far out as the bite_spacing_error_m limit allows), and the
///            gauge's gap is at most `max_gap` (m)
///   vessel   a body to protect: time the energized hook's tip is within `margin` (m) of its
///            nodes is vessel injury (not a task target: it does not count for completion)
///   force_threshold_n   tissue force above which time is counted and damage accrues (default 1.5),
///                       for the tools that declare no damage_force_n of their own
///   reference_path_m    an expert's instrument path for the task (economy of motion); optional
///   metrics  by name (metricCatalogue()): "limit" ≥ 0 (pass or fail), "expert" {mean ≥ 0, sd ≥ 0}
/// Units SI.
#include <Eigen/Core>

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace viscera::sim {

using Vec3 = Eigen::Vector3d;
struct SceneDesc;

/// One metric a trainer uses: its name in the report, unit, which way is better and definition.
struct MetricInfo {
    std::string_view name;
    std::string_view unit;
    bool lowerIsBetter = true;
    std::string_view definition;
};

/// Every metric the player can measure, in report order.
const std::vector<MetricInfo>& metricCatalogue();
/// Null when `name` is not a metric.
const MetricInfo* findMetric(std::string_view name);

struct CutTarget {
    std::vector<Vec3> line; ///< m, scene
    double radius = 0.005;  ///< m
    double coverage = 0.5;  ///< fraction of the line's length to open, (0, 1]
};

struct ClipTarget {
    Vec3 position = Vec3::Zero(); ///< m, scene
    double tolerance = 0.008;     ///< m
    int count = 1;
};

struct SutureTarget {
    Vec3 planePoint = Vec3::Zero();
    Vec3 planeNormal = Vec3::UnitZ(); ///< unit
    int bites = 1;
    double depthMin = 0.001, depthMax = 0.006;     ///< m
    double spacingMin = 0.001, spacingMax = 0.012; ///< m
    double maxGap = 0.0005;                        ///< m
};

/// A vessel to protect: the energized hook's tip within `margin` (m) of any of the body's nodes
/// injures it (metric vessel_injury_s).
struct VesselTarget {
    std::string body;
    double margin = 0.0015; ///< m
};

struct ExpertLevel {
    double mean = 0, sd = 0;
};

struct MetricLevel {
    std::string name; ///< a catalogue name
    std::optional<double> limit;
    std::optional<ExpertLevel> expert;
};

struct AssessmentDesc {
    std::vector<CutTarget> cuts;
    std::vector<ClipTarget> clips;
    std::optional<SutureTarget> suture;
    std::optional<VesselTarget> vessel; ///< not a task target: it does not count for completion
    double forceThresholdN = 1.5;
    std::optional<double> referencePathM;
    std::vector<MetricLevel> metrics; ///< in catalogue order
    const MetricLevel* level(std::string_view name) const;
    bool hasTargets() const { return !cuts.empty() || !clips.empty() || suture.has_value(); }
};

/// The measurability rule: every metric `assessment` judges (a limit or an expert level) can be
/// measured in `scene` (its own assessment is not looked at), and its vessel to protect is one of
/// `bodies` (the scene's body names). One problem per metric or field that breaks it, in
/// catalogue order, each naming the field, what it needs and that the scene has none:
///   "assessment.metrics.out_of_view_s: needs a laparoscope (this scene has none: no session
///    could measure it)"
/// out_of_view_s needs a laparoscope; instrument_collisions two tools; path_length_left_m /
/// path_length_right_m a tool in that hand; angular_path_rad an instrument or probe through a
/// port; final_gap_m a suture with a gauge; max_thread_tension_n a suture; the tip metrics
/// (path_length_m, economy_of_motion, jerk_rms_m_s3, idle_time_s, force_*, tissue_damage_ns) a
/// tool. Empty when the scene can measure everything. The scene reader (checkAssessmentMeasurable)
/// and the studio's typed assessment edits apply it.
std::vector<std::string> unmeasurableMetrics(const AssessmentDesc& assessment, const SceneDesc& scene,
                                             const std::vector<std::string>& bodies);

} // namespace viscera::sim
