#pragma once
/// The JSON readers and writers of the scene model, one per section, shared by the case's
/// scene.json (parseScene, formatScene) and the studio's project.json (studio/project): a field
/// that both files carry is read and written by the same pair of functions here, so the studio
/// and the player apply one rule. Every writer gives back what its reader reads (defaults written
/// explicitly). Every error is "<origin>: <JSON path>: <rule>" (sim/util/json_reader.hpp).
///
/// Header for .cpp files only (nlohmann::json).
#include "sim/scene/scene.hpp"
#include "sim/util/json_reader.hpp"

#include <set>
#include <string>
#include <string_view>

namespace viscera::sim {

/// "solver" (type and XPBD settings; "fem" takes dt only) and "gravity" of `doc`, checked
/// against the ranges of sim/xpbd/xpbd_settings.hpp; also which sections the solver admits
/// ("suture" with fem only and required there, "interaction" with xpbd only).
void readSolver(const JsonField& doc, SceneDesc& scene);
/// Writes "solver" and "gravity" into the document `doc`.
void writeSolver(const SceneDesc& scene, nlohmann::json& doc);
std::optional<AccuracySampling> readAccuracy(const JsonField& doc);
/// Writes "accuracy" into `doc` when `accuracy` is set.
void writeAccuracy(const std::optional<AccuracySampling>& accuracy, nlohmann::json& doc);
/// "steps": the task's ordered steps (kMaxSteps at most, each non-empty displayText of at most
/// kMaxStepBytes). writeSteps writes "steps" into `doc` when there are any.
std::vector<std::string> readSteps(const JsonField& steps);
void writeSteps(const std::vector<std::string>& steps, nlohmann::json& doc);
/// The name rule of bodies, surfaces and tools: 1–64 characters of [A-Za-z0-9_-] (it names the
/// files of the case), unique among all of them (`names`).
std::string readName(const JsonField& name, std::set<std::string>& names);
/// A "port" block (sim/scene/port.hpp); marks it declared.
void readPort(const JsonField& port, PortDesc& out);
void writePort(const PortDesc& port, nlohmann::json& block);
/// "scenery" (render-only surfaces); names unique with the others. Writes it when there is any.
std::vector<SceneryDesc> readScenery(const JsonField& scenery, std::set<std::string>& names);
void writeScenery(const std::vector<SceneryDesc>& scenery, nlohmann::json& doc);
/// "laparoscope" (laparoscope.hpp): its port and the rest tip within the port's insertion.
LaparoscopeDesc readLaparoscope(const JsonField& scope);
/// "assessment" (assessment.hpp): targets, metric limits and expert levels.
AssessmentDesc readAssessment(const JsonField& assessment);
/// Every metric the assessment judges can be measured in `scene`, and its vessel to protect is one
/// of `bodies` (the scene's body names): the rule of unmeasurableMetrics (assessment.hpp). Throws
/// viscera::InputError listing every problem, joined by "; ": "<origin>: assessment.metrics.
/// out_of_view_s: needs a laparoscope (...); assessment.metrics.instrument_collisions: needs two tools (...)".
void checkAssessmentMeasurable(const SceneDesc& scene, const std::vector<std::string>& bodies,
                               const std::string& origin);
void writeAssessment(const AssessmentDesc& assessment, nlohmann::json& doc);
void writeLaparoscope(const LaparoscopeDesc& scope, nlohmann::json& doc);
/// The common fields of a "device" block (hand, motion_scale, force_scale, max_force_n); marks it
/// declared. The caller checks the block's key set.
void readDeviceMapping(const JsonField& device, DeviceMapping& out);
/// Writes those fields into the block `device`.
void writeDeviceMapping(const DeviceMapping& mapping, nlohmann::json& device);
/// "tools" (haptic sphere probes, tool_probe.hpp; at most 2), names unique with the others.
std::vector<ToolDesc> readTools(const JsonField& tools, std::set<std::string>& names);
/// Writes "tools" into `doc` when there are any.
void writeTools(const std::vector<ToolDesc>& tools, nlohmann::json& doc);
/// The body fields both files carry: name, material, strain_limits, embedded_in,
/// embedding_compliance (the caller checks the object's key set).
void readBodyCommon(const JsonField& body, BodyDesc& out, std::set<std::string>& names);
/// Writes those fields into the body object `body` (embedding_compliance with embedded_in, or
/// when not 0).
void writeBodyCommon(const BodyDesc& desc, nlohmann::json& body);
/// The surface fields both files carry: name, areal_density, stretch_stiffness,
/// attach_distance, attach_compliance.
void readSurfaceCommon(const JsonField& surface, SurfaceDesc& out, std::set<std::string>& names);
void writeSurfaceCommon(const SurfaceDesc& desc, nlohmann::json& surface);
/// Cross-references: every embedded_in names another body; the interaction's clip targets and
/// tissue layers name bodies or surfaces (checkInteractionNames). Non-owning views, so that the
/// studio checks its bodies without copying them into a scene.
void checkSceneReferences(const std::vector<const BodyDesc*>& bodies, const std::vector<const SurfaceDesc*>& surfaces,
                          const InteractionDesc* interaction, const std::string& origin);

/// The "material" object (material_json.cpp):
///
///   {"model": "stable_neo_hookean" | "neo_hookean" | "linear" | "st_venant_kirchhoff" |
///             "corotated" | "valanis_landel",
///    "youngs_modulus": 3000, "poisson_ratio": 0.45, "density": 1050,
///    "curves": {"preset": "neo_hookean"}                              (valanis_landel only)
///           | {"f_prime": {"points": [[0.5, -900], [1, 0], [2, 2400]]},
///              "h_prime": {"points": [...], "unconstrained": true}}}
///
/// Ranges: sim::MaterialLimits; the other material rules: sim::validate(Material); curve rules
/// are checked when the material becomes constraints.
Material readMaterial(const JsonField& material);
nlohmann::json materialJson(const Material& m);

/// The interaction section; instrument tracks are paths (inside the case or the project folder).
InteractionDesc readInteractionSection(const JsonField& section);
nlohmann::json interactionJson(const InteractionDesc& desc);

nlohmann::json sceneJson(const SceneDesc& scene);

/// The suture section (sim/suture/suture_scene.cpp); `readTrajectory` false leaves
/// "trajectory" to the caller (a project's trajectory is an object, a scene's a path inside
/// the case).
SutureSceneDesc readSutureSection(const JsonField& section, bool readTrajectory = true);
nlohmann::json sutureJson(const SutureSceneDesc& desc);

} // namespace viscera::sim
