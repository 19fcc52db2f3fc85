#pragma once
/// A studio project: projects/<name>/project.json plus its source meshes. The studio exports it
/// to a .vcase case package (exportCase). Parsing is strict; every error names the file, the
/// field and the rule ("project.json: bodies[0].fixed.min: must be an array of 3 numbers").
///
/// {
///   "schemaVersion": 1,
///   "caseId": "tissue-slab", "caseVersion": "1.0.0", "title": "…", "instructions": "…",
///   "solver": {"type": "xpbd", "dt": 0.0166667, "substeps": 10, "iterations": 1, "damping": 1.0},
///   "gravity": [0, 0, -9.81],
///   "bodies": [{
///     "name": "slab",
///     "mesh": {"generator": "box", "origin": [0,0,0], "size": [0.1,0.02,0.04], "cells": [20,4,8]}
///          | {"generator": "ellipsoid", "center": [..], "radii": [..], "slices": 48, "stacks": 24,
///             "meshing": {..}}
///          | {"generator": "liver", "center": [..], "half_size": [..], "wedge": 0.5, "meshing": {..}}
///          | {"generator": "tube", "start": [..], "end": [..], "radius": 0.004, "meshing": {..}}
///          | {"generator": "hollow_tube", "start": [..], "end": [..], "inner_radius": 0.0038,
///             "outer_radius": 0.005, "slices": 33, "layers": 2, "rings": 8}   (structured, no CGAL)
///          | {"file": "liver.obj", "scale": 0.001, "meshing": {..}},
///     "material": {see readMaterial in core/sim/scene/scene_json.hpp},
///     "fixed": {"min": [..], "max": [..]},     nodes inside this box (metres) are fixed
///     "stiffness_regions": [{"min": [..], "max": [..], "weight": 4}],
///     "stiffness_paint": {"skeleton": {"min_edge_length_rel": 0.002, "medially_centered": true},
///                         "base_weight": 1, "min_weight": 0.001, "max_weight": 1e6,
///                         "strokes": [{"center": [..], "radius": 0.02, "amplitude": 4,
///                                      "scale": "peak" | "kernel"}]},   weights × region weights
///     "embedded_in": "organ", "embedding_compliance": 0
///   }],
///   "surfaces": [{"name": "fascia", "from_boundary_of": "organ", "region": {"min": .., "max": ..},
///                 "areal_density": 0.1, "stretch_stiffness": 50, "attach_distance": 0.001}],
///   "accuracy": {"every_frames": 60, "max_iterations": 100},
///   "suture": {...the scene's suture section (core/sim/suture/suture_scene.hpp), with
///              "trajectory": {"generator": "anastomosis", "stitches": 5, ...AnastomosisSpec fields}
///                          | {"file": "needle.traj"}}     with "solver": {"type": "fem", "dt": ..}
///   "interaction": {...the scene's interaction section (core/sim/scene/interaction.hpp), with
///                   every instrument's "track" a file of the project folder}
/// }
/// The suture trajectory is generated (or read and checked) at load and exported as
/// tools/needle.traj; instrument tracks are checked at load and exported as tools/<name>.track.
/// "meshing" (CGAL Mesh_3, metres and degrees): facet_angle, facet_size, facet_distance,
/// cell_radius_edge_ratio, cell_size, seed.
#include "bake/skeleton.hpp"
#include "bake/tetrahedralize.hpp"
#include "sim/material/material.hpp"
#include "sim/mesh/generators.hpp"
#include "sim/mesh/tet_mesh.hpp"
#include "sim/scene/interaction.hpp"
#include "sim/scene/scene.hpp"
#include "sim/skeleton/stiffness_paint.hpp"
#include "sim/xpbd/xpbd_solver.hpp"

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace viscera::studio {

struct MeshSource {
    enum class Kind { Box, Ellipsoid, Liver, Tube, HollowTube, File };
    Kind kind = Kind::Box;
    sim::HollowTubeSpec hollow; ///< Kind::HollowTube
    sim::BoxSpec box;
    sim::Vec3 center = sim::Vec3::Zero(), radii = sim::Vec3::Constant(0.05); ///< tube: center = start
    sim::Vec3 end = sim::Vec3::Zero();                                       ///< tube end
    double radius = 0.005;                                                   ///< tube radius, m
    double wedge = 0.5;                                                      ///< liver thickness ratio
    int slices = 48, stacks = 24;
    std::filesystem::path file; ///< absolute, resolved against the project folder
    double scale = 1.0;
    bake::MeshingParams meshing;
};

/// Nodes inside an axis-aligned box get a stiffness weight (the skeleton brush comes later).
struct StiffnessRegion {
    sim::Vec3 min, max; ///< metres
    double weight = 1;  ///< > 0; multiplies the material's stiffness
};

/// Skeleton stiffness painting [A §4.3.5]: the body's curve skeleton (mean curvature flow) maps
/// every node to skeleton nodes; poly6 brush strokes on the skeleton set per-node weights.
struct StiffnessPaintProject {
    bake::SkeletonParams skeleton;
    sim::PaintParams params;
    std::vector<sim::BrushStroke> strokes;
};

/// A tet body: its scene description (what the case's scene.json carries: name, material,
/// strain limits, embedding; read by the same code as the player's scene) plus what only
/// authoring needs. meshPath, fixedNodes and nodeWeights of `scene` are filled at export.
struct BodyProject {
    sim::BodyDesc scene;
    MeshSource mesh;
    std::optional<std::array<sim::Vec3, 2>> fixedBox; ///< {min, max}, metres
    std::vector<StiffnessRegion> stiffnessRegions;
    std::optional<StiffnessPaintProject> paint; ///< exported as meshes/<body>.vweights
};

/// A fascia layer cut from the boundary of a tet body (scene.attachTo, "from_boundary_of" in
/// project.json): the boundary triangles whose centroid lies in `region` (all when absent), with
/// their own particles, attached back to the body. meshPath of `scene` is filled at export.
struct SurfaceProject {
    sim::SurfaceDesc scene;
    std::optional<std::array<sim::Vec3, 2>> region;
};

/// The project model the studio edits and exports: the scene description the player reads
/// (`scene`: solver, gravity, accuracy, render, suture with its trajectory text, interaction
/// with its track texts; its bodies and surfaces live in `bodies` / `surfaces` with their
/// authoring settings) plus the case header.
struct Project {
    std::filesystem::path dir;
    int schemaVersion = 1;
    std::string caseId, caseVersion, title;
    sim::SceneDesc scene; ///< bodies and surfaces empty: see below
    std::vector<BodyProject> bodies;
    std::vector<SurfaceProject> surfaces;
};

/// Reads <dir>/project.json. Throws viscera::InputError.
Project loadProject(const std::filesystem::path& dir);

struct BodyExport {
    std::string name;
    size_t nodes = 0, tets = 0, fixedNodes = 0;
    sim::QualityReport quality;
};

struct ExportResult {
    std::filesystem::path casePath;
    uint64_t bytes = 0;
    std::vector<std::string> features;
    std::vector<BodyExport> bodies;
};

using ExportProgress = std::function<void(const std::string& stage)>;

/// Builds every body mesh (generator or import + tetrahedralization), checks its quality (an
/// inverted or degenerate element is an error naming the body and element), resolves fixed
/// regions to node lists, and writes the case package atomically. Only what the scene uses is
/// packaged, and the manifest's features list only the subsystems the scene needs.
ExportResult exportCase(const Project& project, const std::filesystem::path& out, const ExportProgress& progress = {});

/// Builds one body's tet mesh from its source (exposed for the import command and tests).
std::unique_ptr<sim::TetMesh> buildBodyMesh(const BodyProject& body, const std::string& origin);

} // namespace viscera::studio
