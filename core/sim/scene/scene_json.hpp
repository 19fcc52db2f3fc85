#pragma once
/// The JSON readers and writers of the scene model, one per section, shared by the case's
/// scene.json (parseScene) and the studio's project.json (studio/project): a field that both
/// files carry is read by the same function here, so the studio and the player apply one rule.
/// Every error is "<origin>: <JSON path>: <rule>" (sim/util/json_reader.hpp).
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
std::optional<AccuracySampling> readAccuracy(const JsonField& doc);
/// The name rule of bodies, surfaces and tools: 1–64 characters of [A-Za-z0-9_-] (it names the
/// files of the case), unique among all of them (`names`).
std::string readName(const JsonField& name, std::set<std::string>& names);
/// The body fields both files carry: name, material, strain_limits, embedded_in,
/// embedding_compliance (the caller checks the object's key set).
void readBodyCommon(const JsonField& body, BodyDesc& out, std::set<std::string>& names);
/// The surface fields both files carry: name, areal_density, stretch_stiffness,
/// attach_distance, attach_compliance.
void readSurfaceCommon(const JsonField& surface, SurfaceDesc& out, std::set<std::string>& names);
/// Cross-references: embedded_in and attach_to name other bodies, interaction names.
void checkSceneReferences(const SceneDesc& scene, const std::string& origin);

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
