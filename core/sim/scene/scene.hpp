#pragma once
/// Scene description carried by a case (scene.json): solver settings, tet bodies (fat, organs,
/// embedded vessels), surface layers (fascia) and what couples them [A §4.2]. Parsing is strict;
/// every error names the origin, the field and the rule.
///
/// {
///   "solver": {"type": "xpbd", "dt": 0.0166667, "substeps": 10, "iterations": 1,
///              "damping": 1.0, "max_speed": 20.0, "threads": 2},
///   "gravity": [0, 0, -9.81],
///   "instructions": "Watch the slab settle under gravity.",
///   "steps": ["Lift the fundus", "Clip the duct twice"],   optional: the task's ordered steps
///   "accuracy": {"every_frames": 60, "max_iterations": 100},          optional
///   "bodies": [{"name": "organ", "mesh": "meshes/organ.vtet",
///               "material": {...see scene_json.hpp, readMaterial...},
///               "fixed_nodes": [0, 1, 2],
///               "node_weights": [1.0, ...],                            optional, one per node
///               "node_weights_file": "meshes/organ.vweights",         optional, instead
///               "sample_map_file": "maps/organ.vsamples",            optional: painted light
///                                  samples, only with "render": {"sampling": "painted"}
///               "strain_limits": {"axes": [[1,0,0],[0,1,0],[0,0,1]],   optional
///                                 "limits": [{"i": 0, "j": 0, "upper": 0.2, "compliance": 0}]},
///               "embedded_in": "fat", "embedding_compliance": 0}],   optional
///   "surfaces": [{"name": "fascia", "mesh": "meshes/fascia.vtri", "areal_density": 0.1,
///                 "stretch_stiffness": 50, "attach_to": "organ", "attach_distance": 0.001,
///                 "attach_compliance": 0, "fixed_nodes": [],
///                 "node_weights_file": "meshes/fascia.vweights"}],   optional (or "node_weights"):
///                                  painted stiffness, one weight per vertex
///   "tools": [{"name": "probe", "shape": "sphere", ...see tool_probe.hpp...}]   optional
///   "laparoscope": {...see scene/laparoscope.hpp...}   optional: the camera on its port
///   "scenery": [{"name": "pelvic_wall", "mesh": "meshes/pelvic_wall.vtri"}]   optional: drawn only
///   "interaction": {...see scene/interaction.hpp...}   optional, xpbd: instruments on recorded
///              tracks (grasper, energy hook, clip applier) and the tissues the hook can cut
///   "suture": {...see suture/suture_scene.hpp...}   with "solver": {"type": "fem", "dt": ..}: the
///              bodies are one quasi-static corotational FEM (E, ν of their material) with a needle
///   "render": {"sss": true, "sampling": "distance", "stereo": "off",                optional
///              "post": {"tone_mapping": true, ...}}   (checked by render/case_settings.hpp)
/// }
#include "sim/material/material.hpp"
#include "sim/scene/assessment.hpp"
#include "sim/scene/interaction.hpp"
#include "sim/scene/laparoscope.hpp"
#include "sim/scene/tool_probe.hpp"
#include "sim/suture/suture_scene.hpp"
#include "sim/xpbd/strain_limit.hpp"
#include "sim/xpbd/xpbd_settings.hpp"

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace viscera::sim {

struct BodyDesc {
    std::string name;
    std::string meshPath; ///< path of the .vtet inside the case
    Material material;
    std::vector<int32_t> fixedNodes;
    std::vector<double> nodeWeights; ///< empty = all 1
    /// "node_weights_file": a .vweights file inside the case (skeleton stiffness painting,
    /// sim/skeleton/node_weights_io.hpp); whoever reads the case fills nodeWeights from it.
    std::string nodeWeightsPath;
    /// "sample_map_file": a .vsamples file inside the case, the painted light-sample class of
    /// every node (render/sample_map.hpp) [A §6.3.2]. The simulation does not read it; the
    /// player loads it when the render block asks for painted sampling and refuses it otherwise.
    std::string sampleMapPath;
    std::optional<TetStrainLimits> strainLimits;
    std::string embeddedIn; ///< name of the cage body; empty = free-standing
    double embeddingCompliance = 0;
};

struct SurfaceDesc {
    std::string name;
    std::string meshPath;           ///< path of the .vtri inside the case
    double arealDensity = 0.1;      ///< kg/m^2
    double stretchStiffness = 50.0; ///< N/m
    std::string attachTo;           ///< tet body name; empty = free
    double attachDistance = 1e-3;   ///< m
    double attachCompliance = 0;    ///< m/N
    std::vector<int32_t> fixedNodes;
    /// Stiffness painted on the layer's triangles (polygon paint [A §4.3.5, Fig. 4.11]): empty
    /// (all 1) or one weight per vertex, "node_weights"; or "node_weights_file", a .vweights entry
    /// of the case that whoever reads the case loads into nodeWeights. A triangle's stiffness is
    /// stretchStiffness × the mean of its vertices' weights.
    std::vector<double> nodeWeights;
    std::string nodeWeightsPath;
};

struct AccuracySampling {
    int everyFrames = 60;    ///< measure frames 0, every, 2·every, ...
    int maxIterations = 100; ///< XPBD iterations recorded per sampled frame
};

/// The scene's instructions to the trainee: printable UTF-8 text of at most this many bytes
/// (JsonField::displayText), one rule for scene.json and project.json.
inline constexpr size_t kMaxInstructionsBytes = 2000;
/// The task's ordered steps shown to the trainee as a numbered list ("steps", optional, default
/// none): at most kMaxSteps steps, each non-empty printable UTF-8 text of at most kMaxStepBytes
/// bytes (JsonField::displayText, the instructions' rule), one rule for scene.json and project.json
/// (sim::readSteps).
inline constexpr size_t kMaxSteps = 20;
inline constexpr size_t kMaxStepBytes = 200;

/// A surface of the case that is drawn and never simulated: the anatomy around the working space
/// (pelvic side walls, peritoneum, an organ the task does not touch). It costs no physics; a
/// render.materials entry of its name gives it maps, as for a body.
///   "scenery": [{"name": "pelvic_wall", "mesh": "meshes/pelvic_wall.vtri"}]
struct SceneryDesc {
    std::string name;     ///< unique with the bodies, surfaces and tools
    std::string meshPath; ///< .vtri entry of the case
};

struct SceneDesc {
    std::string instructions;       ///< shown to the trainee; may be empty
    std::vector<std::string> steps; ///< the task's ordered steps, shown numbered; may be empty
    /// The "render" object as JSON text (empty: renderer defaults). The simulation does not read
    /// it; the player checks it at load (render::applyCaseRender) and hands it to the renderer.
    std::string render;
    std::string solverType = "xpbd";
    XpbdSettings xpbd;
    std::optional<AccuracySampling> accuracy;
    std::vector<BodyDesc> bodies;
    std::vector<SurfaceDesc> surfaces;
    std::vector<ToolDesc> tools;           ///< haptic probes (feature "probe")
    std::optional<SutureSceneDesc> suture; ///< solver "fem" only (features fem, needle, thread, contact)
    /// Scripted instruments (features collision, dissection, clip); XPBD scenes only.
    std::optional<InteractionDesc> interaction;
    /// Render-only surfaces (scene "scenery"): drawn with the tissue, never simulated.
    std::vector<SceneryDesc> scenery;
    /// The camera on its port (laparoscope.hpp); without it the renderer frames the tissue.
    std::optional<LaparoscopeDesc> laparoscope;
    /// The task's targets, metric limits and expert levels (assessment.hpp); none: no verdict.
    std::optional<AssessmentDesc> assessment;
};

/// Throws viscera::InputError ("scene.json: bodies[0].material.poisson_ratio: must be in [0, 0.5)").
SceneDesc parseScene(std::string_view json, const std::string& origin);
std::string formatScene(const SceneDesc& scene);

} // namespace viscera::sim
