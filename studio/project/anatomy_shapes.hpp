#pragma once
/// Anatomy a project makes by code around its simulated tissue: render-only scenery surfaces
/// (pelvic side walls, peritoneum, the rectum) and the bend that wraps a flat tissue sheet into a
/// shell around an organ (the mesorectum around the rectum). Parsed and written here, used by the
/// project reader/writer and the export (project.cpp).
///
/// project.json:
///   "bend": {"radius": 0.032, "center_y": 0.01}
///       wraps every body and surface, once generated, fixed and painted flat, about the line
///       along x through (y center_y, z −radius): a point (x, y, z) goes to the angle
///       (y − center_y) / radius from +z (towards +y) at the distance radius + z from the line. A
///       sheet at −t ≤ z ≤ 0 becomes a shell of thickness t over a cylinder of radius radius − t;
///       lengths along its top (z = 0) are kept. Radius in [0.005, 1] m, center_y in [−1, 1] m
///       (default 0); every node must lie
///       above the line's depth (radius + z > 0).
///   "scenery": [{"name": "pelvic_wall", "generator": "cylinder", "start": [..], "end": [..],
///                "radius": 0.075, "from_deg": 60, "to_deg": 300, "slices": 48, "rings": 16},
///               {"name": "peritoneum", "generator": "disc", "center": [..], "normal": [..],
///                "radius": 0.075, "slices": 48, "rings": 8}]
///       render-only surfaces in scene coordinates (not bent), each with an optional "texture"
///       (a body's texture block, read by the project reader), exported as meshes/<name>.vtri and
///       the scene's "scenery" (sim::SceneryDesc). Cylinder: the part of a cylinder around the
///       segment start–end between the angles from_deg and to_deg (0° is the scene's +z across
///       the axis, 90° is axis × (+z); default the whole turn), open at its ends, facing its axis
///       ("facing": "inward", the default: a wall around the working space) or away from it
///       ("outward": an organ). Disc: a flat disc of `radius` centred at `center`, facing
///       `normal`. A scenery surface is drawn from the side it faces only, so from outside the
///       working space (the studio's view) its walls do not hide the tissue. radius (0, 1] m, slices [8, 256],
///       rings [1, 256], angles in [−360, 360] with from < to ≤ from + 360.
#include "sim/mesh/tri_mesh.hpp"
#include "sim/util/json_reader.hpp"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace viscera::studio {

struct BendSpec {
    double radius = 0.032; ///< m
    double centerY = 0;    ///< m: the y of the bend's axis (the line along x at y centerY, z −radius)
};

struct SceneryProject {
    enum class Generator { Cylinder, Disc, File };
    std::string name;
    Generator generator = Generator::Cylinder;
    sim::Vec3 start = sim::Vec3::Zero(), end = sim::Vec3::UnitX();     ///< cylinder axis, m
    sim::Vec3 center = sim::Vec3::Zero(), normal = sim::Vec3::UnitZ(); ///< disc
    double radius = 0.05;
    double fromDeg = 0, toDeg = 360; ///< cylinder
    bool inward = true;              ///< cylinder: faces its axis (a wall seen from inside), else outward
    int slices = 48, rings = 8;
    /// File: a surface of the project folder (OBJ, STL, PLY, glTF, FBX: bake::importSurface's
    /// rules) and the metres per file unit; imported as it is, drawn two-sided.
    std::filesystem::path file;
    double scale = 1.0;
};

BendSpec readBend(const sim::JsonField& bend);
nlohmann::json bendJson(const BendSpec& bend);
/// Where the bend takes `p` (see above).
sim::Vec3 bendPoint(const BendSpec& bend, const sim::Vec3& p);
/// Bends every point of `points` in place. Throws std::invalid_argument naming the first point
/// that lies at or below the line's depth (radius + z <= 0).
void bendPoints(const BendSpec& bend, std::vector<sim::Vec3>& points);

/// "scenery"; names must be new to `names` (bodies, surfaces, tools) and are added to it. A
/// "texture" key is the caller's (Project::sceneryTextures). An imported one:
///   {"name": "liver", "generator": "file", "file": "anatomy/liver.obj", "scale": 0.01}
/// its file inside the project folder `dir` (projectFileOf's rule), scale in (0, 1000].
std::vector<SceneryProject> readSceneryProject(const sim::JsonField& scenery, std::set<std::string>& names,
                                               const std::filesystem::path& dir);
nlohmann::json sceneryJson(const std::vector<SceneryProject>& scenery, const std::filesystem::path& dir);
/// The surface of one scenery entry, in scene coordinates (an imported one read from its file:
/// InputError naming the file, the element and the rule when it is not a surface).
sim::TriMesh scenerySurface(const SceneryProject& s);

} // namespace viscera::studio
