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
///          | {"file": "liver.obj", "scale": 0.001, "meshing": {..}},
///     "material": {"model": "neo_hookean", "youngs_modulus": 3000, "poisson_ratio": 0.45,
///                  "density": 1050},
///     "fixed": {"min": [..], "max": [..]}      nodes inside this box (metres) are fixed
///   }]
/// }
/// "meshing" (CGAL Mesh_3, metres and degrees): facet_angle, facet_size, facet_distance,
/// cell_radius_edge_ratio, cell_size, seed.
#include "bake/tetrahedralize.hpp"
#include "sim/material/material.hpp"
#include "sim/mesh/generators.hpp"
#include "sim/mesh/tet_mesh.hpp"
#include "sim/xpbd/xpbd_solver.hpp"

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace viscera::studio {

struct MeshSource {
    enum class Kind { Box, Ellipsoid, File };
    Kind kind = Kind::Box;
    sim::BoxSpec box;
    sim::Vec3 center = sim::Vec3::Zero(), radii = sim::Vec3::Constant(0.05);
    int slices = 48, stacks = 24;
    std::filesystem::path file; ///< absolute, resolved against the project folder
    double scale = 1.0;
    bake::MeshingParams meshing;
};

struct BodyProject {
    std::string name;
    MeshSource mesh;
    sim::Material material;
    std::optional<std::array<sim::Vec3, 2>> fixedBox; ///< {min, max}, metres
};

struct Project {
    std::filesystem::path dir;
    int schemaVersion = 1;
    std::string caseId, caseVersion, title, instructions;
    sim::XpbdSettings solver;
    std::vector<BodyProject> bodies;
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
ExportResult exportCase(const Project& project, const std::filesystem::path& out,
                        const ExportProgress& progress = {});

/// Builds one body's tet mesh from its source (exposed for the import command and tests).
std::unique_ptr<sim::TetMesh> buildBodyMesh(const BodyProject& body, const std::string& origin);

} // namespace viscera::studio
