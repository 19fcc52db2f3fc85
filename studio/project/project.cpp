#include "project/project.hpp"

#include "project/remesh_cache.hpp"
#include "project/surface_refine.hpp"

#include "bake/texture.hpp"
#include "render/case_references.hpp"
#include "render/case_settings.hpp"

#include "bake/import.hpp"
#include "case/case_writer.hpp"
#include "case/manifest.hpp"
#include "sim/mesh/gmsh_io.hpp"
#include "sim/mesh/tet_io.hpp"
#include "sim/scene/port_reach.hpp"
#include "sim/scene/scene.hpp"
#include "sim/scene/scene_json.hpp"
#include "sim/scene/world.hpp"
#include "sim/skeleton/node_weights_io.hpp"
#include "sim/suture/anastomosis.hpp"
#include "sim/util/atomic_file.hpp"
#include "sim/util/entry_name.hpp"
#include "sim/util/error.hpp"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <nlohmann/json.hpp>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <map>
#include <set>

#include <unistd.h>

namespace viscera::studio {
namespace {

using nlohmann::json;
using sim::JsonField;
using sim::NumberRule;

json vec3Json(const sim::Vec3& v) {
    return {v.x(), v.y(), v.z()};
}

std::array<sim::Vec3, 2> readBox(const JsonField& f) {
    f.object({"min", "max"});
    const sim::Vec3 lo = f["min"].vec3(), hi = f["max"].vec3();
    if (!(lo.array() <= hi.array()).all()) f.fail("min must not exceed max");
    return {lo, hi};
}

/// "fixed": one box, or a list of 1 to kMaxHoldBoxes boxes.
std::vector<std::array<sim::Vec3, 2>> readHoldBoxes(const JsonField& f) {
    if (!f.value().is_array()) return {readBox(f)};
    std::vector<std::array<sim::Vec3, 2>> boxes;
    for (const JsonField& box : f.items(1, kMaxHoldBoxes))
        boxes.push_back(readBox(box));
    return boxes;
}

json boxJson(const std::array<sim::Vec3, 2>& box) {
    return {{"min", vec3Json(box[0])}, {"max", vec3Json(box[1])}};
}

/// The rule every file reference of a project keeps: `file` (dir / a relative path by the
/// entry-name rule) still lies in the project folder once symbolic links are resolved. The rule
/// it breaks, for a message, or empty.
std::string outsideProjectProblem(const std::filesystem::path& dir, const std::filesystem::path& file) {
    if (sim::insideFolder(dir, file)) return {};
    std::error_code ec;
    const std::filesystem::path target = std::filesystem::weakly_canonical(file, ec);
    return "'" + file.string() + "' leads outside the project folder" +
           (ec ? std::string() : " (to '" + target.string() + "')") + "; project files must lie inside it";
}

/// A file of the project folder: a relative path by the entry-name rule (no '..', not
/// absolute) that stays inside the folder through links, so that nothing outside the folder the
/// user gave is read.
std::filesystem::path projectFile(const JsonField& f, const std::filesystem::path& dir) {
    std::filesystem::path file = dir / f.entryPath();
    if (const std::string why = outsideProjectProblem(dir, file); !why.empty()) f.fail(why);
    return file;
}

/// Where the writers of project.json report to: the file and the project folder.
struct WriteContext {
    std::filesystem::path dir;
    std::string origin; ///< <dir>/project.json
};

/// The project.json form of a file of the project (projectFile's inverse): `file` relative to
/// the project folder. Lexical, so that dir / "a/b.obj" gives back "a/b.obj" exactly.
std::string projectFileJson(const std::filesystem::path& file, const WriteContext& w, const std::string& field) {
    return projectRelativePath(file, w.dir, w.origin + ": " + field);
}

bake::MeshingParams readMeshing(const JsonField& mesh) {
    bake::MeshingParams p;
    auto m = mesh.find("meshing");
    if (!m) return p;
    m->object(
        {"facet_angle", "facet_size", "facet_distance", "cell_radius_edge_ratio", "cell_size", "seed", "max_tets"});
    p.facetAngleDeg = m->number("facet_angle", p.facetAngleDeg, NumberRule::positive());
    p.facetSize = m->number("facet_size", p.facetSize, NumberRule::positive());
    p.facetDistance = m->number("facet_distance", p.facetDistance, NumberRule::positive());
    p.cellRadiusEdgeRatio = m->number("cell_radius_edge_ratio", p.cellRadiusEdgeRatio, NumberRule::positive());
    p.cellSize = m->number("cell_size", p.cellSize, NumberRule::positive());
    p.seed = static_cast<unsigned>(m->integer("seed", static_cast<int>(p.seed), 0, 1 << 30));
    // the cap on the tets the sizes may ask for (refused before meshing): at most the default
    p.maxEstimatedTets =
        size_t(m->integer("max_tets", int(p.maxEstimatedTets), 1000, int(bake::MeshingParams{}.maxEstimatedTets)));
    return p;
}

/// The sizes are written when set (0 = derived from the surface, absent in the file).
json meshingJson(const bake::MeshingParams& p) {
    json j = {{"facet_angle", p.facetAngleDeg}, {"cell_radius_edge_ratio", p.cellRadiusEdgeRatio}, {"seed", p.seed}};
    if (p.facetSize > 0) j["facet_size"] = p.facetSize;
    if (p.facetDistance > 0) j["facet_distance"] = p.facetDistance;
    if (p.cellSize > 0) j["cell_size"] = p.cellSize;
    if (p.maxEstimatedTets != bake::MeshingParams{}.maxEstimatedTets) j["max_tets"] = p.maxEstimatedTets;
    return j;
}

sim::Vec3 positiveVec3(const JsonField& f, const char* rule) {
    const sim::Vec3 v = f.vec3();
    if (!(v.array() > 0).all()) f.fail(rule);
    return v;
}

/// The placement fields of a remesh block (RemeshSource::placement): "unit", "scale",
/// "rotation_deg", each optional.
bake::ImportPlacement readPlacement(const JsonField& r) {
    bake::ImportPlacement p;
    if (auto u = r.find("unit"))
        p.unit = *bake::lengthUnitFromName(u->choice({"m", "cm", "mm", "inch"}, "a length unit"));
    p.scale = r.number("scale", p.scale, NumberRule::positive());
    if (auto d = r.find("rotation_deg")) p.rotationDeg = d->vec3(NumberRule::closed(-360, 360));
    return p;
}

void writePlacement(const bake::ImportPlacement& p, json& j) {
    j["unit"] = std::string(bake::unitName(p.unit));
    j["scale"] = p.scale;
    j["rotation_deg"] = vec3Json(p.rotationDeg);
}

/// The "remesh" block (RemeshSource): the numbers by the rules of bake::RemeshParams.
RemeshSource readRemesh(const JsonField& r, const std::filesystem::path& dir) {
    r.object({"parts", "unit", "scale", "rotation_deg", "voxel_size", "voxel_count", "smoothing", "edge_length",
              "iterations", "fill_openings", "uv_transfer", "texture"});
    RemeshSource out;
    const JsonField parts = r["parts"];
    if (!parts.value().is_array() || parts.value().empty() || parts.value().size() > 64)
        parts.fail("must be an array of 1 to 64 parts");
    for (const JsonField& p : parts.items()) {
        p.object({"file", "op"});
        RemeshSource::Part part;
        part.file = projectFile(p["file"], dir);
        const std::string op = p.find("op") ? p["op"].choice({"union", "difference", "intersection"}, "a CSG operation")
                                            : std::string("union");
        part.op = op == "union"        ? bake::CsgOp::Union
                  : op == "difference" ? bake::CsgOp::Difference
                                       : bake::CsgOp::Intersection;
        out.parts.push_back(part);
    }
    out.placement = readPlacement(r);
    bake::RemeshParams& q = out.params;
    if (r.find("voxel_size") && r.find("voxel_count")) r.fail("give voxel_size or voxel_count, not both");
    q.voxelSize = r.number("voxel_size", 0.0, NumberRule::positive());
    q.voxelCount = r.integer("voxel_count", q.voxelCount, 8, q.maxVoxelsPerAxis);
    q.smoothingIterations = r.integer("smoothing", q.smoothingIterations, 0, 100);
    q.targetEdgeLength = r.number("edge_length", 0.0, NumberRule::positive());
    q.remeshIterations = r.integer("iterations", q.remeshIterations, 0, 20);
    q.fillOpenings = r.number("fill_openings", 0.0, NumberRule::aboveUpTo(0, 1));
    if (auto u = r.find("uv_transfer")) {
        const std::string m = u->choice({"seam-cut", "closest", "island", "none"}, "a UV transfer method");
        out.uvTransfer = m == "none"      ? std::nullopt
                         : m == "closest" ? std::optional(bake::UvTransferMethod::ClosestPoint)
                         : m == "island"  ? std::optional(bake::UvTransferMethod::IslandLabelled)
                                          : std::optional(bake::UvTransferMethod::SeamCutting);
    }
    if (auto t = r.find("texture")) {
        out.texture = projectFile(*t, dir);
        if (out.texture.extension() != ".png") t->fail("must be a PNG image (.png)");
        if (!out.uvTransfer) t->fail("needs UVs: uv_transfer is 'none'");
    }
    return out;
}

json remeshJson(const RemeshSource& r, const WriteContext& w, const std::string& field) {
    json parts = json::array();
    for (size_t i = 0; i < r.parts.size(); ++i)
        parts.push_back(
            {{"file", projectFileJson(r.parts[i].file, w, field + ".parts[" + std::to_string(i) + "].file")},
             {"op", std::string(bake::csgOpName(r.parts[i].op))}});
    json j = {{"parts", parts},
              {"smoothing", r.params.smoothingIterations},
              {"iterations", r.params.remeshIterations},
              {"uv_transfer", r.uvTransfer ? (*r.uvTransfer == bake::UvTransferMethod::ClosestPoint     ? "closest"
                                              : *r.uvTransfer == bake::UvTransferMethod::IslandLabelled ? "island"
                                                                                                        : "seam-cut")
                                           : "none"}};
    if (r.params.voxelSize > 0)
        j["voxel_size"] = r.params.voxelSize;
    else
        j["voxel_count"] = r.params.voxelCount;
    if (r.params.targetEdgeLength > 0) j["edge_length"] = r.params.targetEdgeLength;
    if (r.params.fillOpenings > 0) j["fill_openings"] = r.params.fillOpenings;
    if (!r.texture.empty()) j["texture"] = projectFileJson(r.texture, w, field + ".texture");
    writePlacement(r.placement, j);
    return j;
}

MeshSource readMeshSource(const JsonField& m, const std::filesystem::path& dir) {
    MeshSource s;
    if (m.anyObject().has("remesh")) {
        m.object({"remesh", "meshing"});
        s.kind = MeshSource::Kind::Remesh;
        s.remesh = readRemesh(m["remesh"], dir);
        s.meshing = readMeshing(m);
        return s;
    }
    if (m.anyObject().has("file")) {
        s.kind = MeshSource::Kind::File;
        s.file = projectFile(m["file"], dir);
        // a tetrahedral mesh (.msh, .vtu, .vtet) is simulated as it is: nothing to mesh
        const bool tets = sim::isTetFile(s.file);
        tets ? m.object({"file", "scale"}) : m.object({"file", "scale", "meshing"});
        s.scale = m.number("scale", s.scale, NumberRule::positive());
        if (!tets) s.meshing = readMeshing(m);
        return s;
    }
    const std::string gen =
        m["generator"].choice({"box", "ellipsoid", "liver", "tube", "hollow_tube"}, "a known generator");
    if (gen == "box") {
        m.object({"generator", "origin", "size", "cells"});
        s.kind = MeshSource::Kind::Box;
        if (auto v = m.find("origin")) s.box.origin = v->vec3();
        s.box.size = positiveVec3(m["size"], "every edge length must be positive");
        const JsonField cells = m["cells"];
        if (!cells.value().is_array() || cells.value().size() != 3) cells.fail("must be an array of 3 integers");
        const std::vector<JsonField> c = cells.items();
        for (int k = 0; k < 3; ++k)
            s.box.cells[k] = c[k].integer(1, 512);
    } else if (gen == "ellipsoid" || gen == "liver") {
        const bool liver = gen == "liver";
        liver ? m.object({"generator", "center", "half_size", "wedge", "slices", "stacks", "meshing"})
              : m.object({"generator", "center", "radii", "slices", "stacks", "meshing"});
        s.kind = liver ? MeshSource::Kind::Liver : MeshSource::Kind::Ellipsoid;
        if (auto v = m.find("center")) s.center = v->vec3();
        s.radii = liver ? positiveVec3(m["half_size"], "every half size must be positive")
                        : positiveVec3(m["radii"], "every radius must be positive");
        if (liver) s.wedge = m.number("wedge", s.wedge, NumberRule::aboveUpTo(0, 1));
        s.slices = m.integer("slices", s.slices, 3, 1024);
        s.stacks = m.integer("stacks", s.stacks, 2, 1024);
        s.meshing = readMeshing(m);
    } else if (gen == "tube") {
        m.object({"generator", "start", "end", "radius", "slices", "rings", "meshing"});
        s.kind = MeshSource::Kind::Tube;
        s.center = m["start"].vec3();
        s.end = m["end"].vec3();
        s.radius = m["radius"].number(NumberRule::positive());
        if ((s.end - s.center).norm() <= 0) m.fail("end must differ from start");
        s.slices = m.integer("slices", s.slices, 3, 1024);
        s.stacks = m.integer("rings", s.stacks, 1, 1024);
        s.meshing = readMeshing(m);
    } else {
        m.object({"generator", "start", "end", "inner_radius", "outer_radius", "slices", "layers", "rings"});
        s.kind = MeshSource::Kind::HollowTube;
        s.hollow.start = m["start"].vec3();
        s.hollow.end = m["end"].vec3();
        if ((s.hollow.end - s.hollow.start).norm() <= 0) m.fail("end must differ from start");
        s.hollow.innerRadius = m["inner_radius"].number(NumberRule::positive());
        s.hollow.outerRadius = m["outer_radius"].number(NumberRule::positive());
        if (!(s.hollow.outerRadius > s.hollow.innerRadius)) m.fail("outer_radius must exceed inner_radius");
        s.hollow.slices = m.integer("slices", s.hollow.slices, 3, 1024);
        s.hollow.layers = m.integer("layers", s.hollow.layers, 1, 64);
        s.hollow.rings = m.integer("rings", s.hollow.rings, 1, 1024);
    }
    return s;
}

json meshSourceJson(const MeshSource& s, const WriteContext& w, const std::string& field) {
    using K = MeshSource::Kind;
    switch (s.kind) {
    case K::Remesh:
        return {{"remesh", remeshJson(s.remesh, w, field + ".remesh")}, {"meshing", meshingJson(s.meshing)}};
    case K::File:
        if (sim::isTetFile(s.file)) return {{"file", projectFileJson(s.file, w, field + ".file")}, {"scale", s.scale}};
        return {{"file", projectFileJson(s.file, w, field + ".file")},
                {"scale", s.scale},
                {"meshing", meshingJson(s.meshing)}};
    case K::Box:
        return {{"generator", "box"},
                {"origin", vec3Json(s.box.origin)},
                {"size", vec3Json(s.box.size)},
                {"cells", s.box.cells}};
    case K::Ellipsoid:
        return {{"generator", "ellipsoid"}, {"center", vec3Json(s.center)}, {"radii", vec3Json(s.radii)},
                {"slices", s.slices},       {"stacks", s.stacks},           {"meshing", meshingJson(s.meshing)}};
    case K::Liver:
        return {{"generator", "liver"},
                {"center", vec3Json(s.center)},
                {"half_size", vec3Json(s.radii)},
                {"wedge", s.wedge},
                {"slices", s.slices},
                {"stacks", s.stacks},
                {"meshing", meshingJson(s.meshing)}};
    case K::Tube:
        return {{"generator", "tube"},
                {"start", vec3Json(s.center)},
                {"end", vec3Json(s.end)},
                {"radius", s.radius},
                {"slices", s.slices},
                {"rings", s.stacks},
                {"meshing", meshingJson(s.meshing)}};
    case K::HollowTube:
        return {{"generator", "hollow_tube"},
                {"start", vec3Json(s.hollow.start)},
                {"end", vec3Json(s.hollow.end)},
                {"inner_radius", s.hollow.innerRadius},
                {"outer_radius", s.hollow.outerRadius},
                {"slices", s.hollow.slices},
                {"layers", s.hollow.layers},
                {"rings", s.hollow.rings}};
    }
    throw InputError(w.origin + ": " + field + ": unknown mesh source");
}

/// {"generator": "anastomosis", ...}: the trajectory fields of the spec.
sim::AnastomosisSpec readAnastomosisTrajectory(const JsonField& t) {
    t["generator"].choice({"anastomosis"}, "a known generator");
    t.object({"generator", "stitches", "needle_radius", "needle_centre", "degrees_per_frame", "transfer_frames",
              "transfer_distance", "pull_frames", "pull_per_segment", "slack"});
    sim::AnastomosisSpec a;
    a.stitches = t.integer("stitches", a.stitches, 1, 64);
    a.needleRadius = t.number("needle_radius", a.needleRadius, NumberRule::positive());
    a.needleCentre = t.number("needle_centre", a.needleCentre, NumberRule::positive());
    a.degreesPerFrame = t.number("degrees_per_frame", a.degreesPerFrame, NumberRule::aboveUpTo(0, 90));
    a.transferFrames = t.integer("transfer_frames", a.transferFrames, 1, 10000);
    a.transferDistance = t.number("transfer_distance", a.transferDistance, NumberRule::positive());
    a.pullFrames = t.integer("pull_frames", a.pullFrames, 1, 100000);
    a.pullPerSegment = t.number("pull_per_segment", a.pullPerSegment, NumberRule::positive());
    a.slack = t.number("slack", a.slack);
    return a;
}

json anastomosisTrajectoryJson(const sim::AnastomosisSpec& a) {
    return {{"generator", "anastomosis"},
            {"stitches", a.stitches},
            {"needle_radius", a.needleRadius},
            {"needle_centre", a.needleCentre},
            {"degrees_per_frame", a.degreesPerFrame},
            {"transfer_frames", a.transferFrames},
            {"transfer_distance", a.transferDistance},
            {"pull_frames", a.pullFrames},
            {"pull_per_segment", a.pullPerSegment},
            {"slack", a.slack}};
}

/// The suture section: the scene's section (sim::readSutureSection) whose trajectory is
/// generated (anastomosis) or read from a project file, checked, and exported as
/// tools/needle.traj. `source` keeps where it came from.
sim::SutureSceneDesc readSutureProject(const JsonField& su, const std::filesystem::path& dir,
                                       TrajectorySource& source) {
    sim::SutureSceneDesc d = sim::readSutureSection(su, /*readTrajectory=*/false);
    const JsonField t = su["trajectory"];
    t.anyObject();
    source = {};
    if (auto file = t.find("file")) {
        t.object({"file"});
        source.file = projectFile(*file, dir);
        d.trajectoryText = readFile(source.file);
        sim::parseTrajectory(d.trajectoryText, source.file.string()); // checked now, not in the player
    } else {
        source.generator = readAnastomosisTrajectory(t);
        d.trajectoryText = sim::formatTrajectory(sim::makeAnastomosisTrajectory(*source.generator));
    }
    d.trajectoryPath = "tools/needle.traj";
    return d;
}

/// The scene's suture section (sim::sutureJson) with the project's "trajectory".
json sutureProjectJson(const sim::SutureSceneDesc& d, const TrajectorySource& source, const WriteContext& w) {
    json j = sim::sutureJson(d);
    // Not a conditional expression with a braced json{...}: its initializer list's temporaries end
    // before the conditional's result is copied (AddressSanitizer: stack-use-after-scope).
    if (source.generator) {
        j["trajectory"] = anastomosisTrajectoryJson(*source.generator);
    } else {
        json file = json::object();
        file["file"] = projectFileJson(source.file, w, "suture.trajectory.file");
        j["trajectory"] = std::move(file);
    }
    return j;
}

/// "stiffness_paint" of a body (skeleton: true) or of a fascia surface (polygon paint, no skeleton).
StiffnessPaintProject readPaint(const JsonField& j, bool skeleton) {
    if (skeleton)
        j.object({"skeleton", "base_weight", "min_weight", "max_weight", "strokes"});
    else
        j.object({"base_weight", "min_weight", "max_weight", "strokes"});
    StiffnessPaintProject p;
    if (auto sk = j.find("skeleton")) {
        sk->object({"min_edge_length_rel", "medially_centered", "max_iterations"});
        p.skeleton.minEdgeLengthRel =
            sk->number("min_edge_length_rel", p.skeleton.minEdgeLengthRel, NumberRule::positive());
        p.skeleton.mediallyCentered = sk->boolean("medially_centered", p.skeleton.mediallyCentered);
        p.skeleton.maxIterations =
            static_cast<size_t>(sk->integer("max_iterations", static_cast<int>(p.skeleton.maxIterations), 1, 10000));
    }
    p.params.baseWeight = j.number("base_weight", p.params.baseWeight, NumberRule::positive());
    p.params.minWeight = j.number("min_weight", p.params.minWeight, NumberRule::positive());
    p.params.maxWeight = j.number("max_weight", p.params.maxWeight, NumberRule::positive());
    if (!(p.params.minWeight <= p.params.baseWeight && p.params.baseWeight <= p.params.maxWeight))
        j.fail("min_weight <= base_weight <= max_weight must hold"); // the rule of sim::bakeStiffnessPaint, at load
    p.params.origin = j.origin() + ": " + j.path();
    const std::vector<JsonField> strokes = j["strokes"].items(1);
    for (size_t k = 0; k < strokes.size(); ++k) {
        const JsonField& st = strokes[k];
        if (skeleton)
            st.object({"center", "radius", "amplitude", "scale", "mode", "target", "reach"});
        else
            st.object({"center", "radius", "amplitude", "scale", "mode", "target"});
        sim::BrushStroke s;
        s.center = st["center"].vec3();
        s.radius = st["radius"].number(NumberRule::closed(sim::kMinBrushRadius, sim::kMaxBrushRadius));
        s.amplitude = st["amplitude"].number();
        if (auto sc = st.find("scale"))
            s.scale = sc->choice({"peak", "kernel"}, "a brush scale") == "peak" ? sim::BrushScale::Peak
                                                                                : sim::BrushScale::Kernel;
        if (auto m = st.find("mode")) {
            const std::string mode = m->choice({"add", "subtract", "mix", "smooth"}, "a brush mode");
            s.mode = mode == "add"        ? sim::BrushMode::Add
                     : mode == "subtract" ? sim::BrushMode::Subtract
                     : mode == "mix"      ? sim::BrushMode::Mix
                                          : sim::BrushMode::Smooth;
        }
        if (auto r = st.find("reach")) // "skeleton" (eq. 4.26, the default) or "sphere" (and the nodes touched)
            s.reach = r->choice({"skeleton", "sphere"}, "a brush reach") == "sphere" ? sim::BrushReach::Sphere
                                                                                     : sim::BrushReach::Skeleton;
        if (auto t = st.find("target")) {
            if (s.mode != sim::BrushMode::Mix) t->fail("only a mix stroke has a target");
            s.target = t->number(NumberRule::positive());
        } else if (s.mode == sim::BrushMode::Mix) {
            st.failAt("target", "a mix stroke needs the weight it mixes towards");
        }
        try {
            sim::validateStroke(s, k, st.origin() + ": " + st.path());
        } catch (const std::exception& e) {
            throw InputError(e.what());
        }
        p.strokes.push_back(s);
    }
    return p;
}

json paintJson(const StiffnessPaintProject& p, bool skeleton) {
    json strokes = json::array();
    for (const sim::BrushStroke& s : p.strokes) {
        json j = {{"center", vec3Json(s.center)},
                  {"radius", s.radius},
                  {"amplitude", s.amplitude},
                  {"scale", s.scale == sim::BrushScale::Peak ? "peak" : "kernel"}};
        if (s.mode != sim::BrushMode::Add)
            j["mode"] = s.mode == sim::BrushMode::Subtract ? "subtract"
                        : s.mode == sim::BrushMode::Mix    ? "mix"
                                                           : "smooth";
        if (s.mode == sim::BrushMode::Mix) j["target"] = s.target;
        if (skeleton && s.reach == sim::BrushReach::Sphere) j["reach"] = "sphere";
        strokes.push_back(std::move(j));
    }
    json out = {{"base_weight", p.params.baseWeight},
                {"min_weight", p.params.minWeight},
                {"max_weight", p.params.maxWeight},
                {"strokes", strokes}};
    if (skeleton)
        out["skeleton"] = {{"min_edge_length_rel", p.skeleton.minEdgeLengthRel},
                           {"medially_centered", p.skeleton.mediallyCentered},
                           {"max_iterations", p.skeleton.maxIterations}};
    return out;
}

/// "texture": a body's or surface's generated material maps (TextureProject). A generator is
/// read in full here (bake::parseTextureSpec), so a spec the export cannot bake never loads.
TextureProject readTexture(const JsonField& j, const std::filesystem::path& dir) {
    j.object({"spec", "generator", "tiles_per_metre", "normal_strength"});
    if (j.has("spec") == j.has("generator"))
        j.fail(j.has("spec") ? "takes 'spec' (a file) or 'generator' (the spec itself), not both"
                             : "needs 'spec' (a texture spec file) or 'generator' (the spec itself)");
    TextureProject t;
    if (j.has("spec")) {
        // Inside the project folder, through links too (kept relative: it is written back as given).
        const JsonField spec = j["spec"];
        t.spec = spec.entryPath();
        if (const std::string why = outsideProjectProblem(dir, dir / t.spec); !why.empty()) spec.fail(why);
    } else {
        const JsonField g = j["generator"];
        g.anyObject();
        t.generator = g.value().dump();
        bake::parseTextureSpec(t.generator, j.origin() + ": " + g.path(), dir);
    }
    render::readMapLayout(j, t.tilesPerMetre, t.normalStrength);
    return t;
}

json textureJson(const TextureProject& t) {
    json j = {{"tiles_per_metre", t.tilesPerMetre}, {"normal_strength", t.normalStrength}};
    if (t.generator.empty())
        j["spec"] = t.spec;
    else
        j["generator"] = json::parse(t.generator);
    return j;
}

/// "light_samples": the body's light-sample painting [A §6.3.2], operations replayed in order on
/// its surface at rest (render::applySamplePaint).
std::vector<render::SamplePaintOp> readLightSamples(const JsonField& j) {
    std::vector<render::SamplePaintOp> ops;
    for (const JsonField& o : j.items()) {
        render::SamplePaintOp op;
        const std::string tool = o["tool"].choice({"brush", "fill"}, "a light-sample tool");
        op.samples = o["samples"].integer(0, 8);
        if (!render::isSampleClass(op.samples)) o.failAt("samples", "must be 0 (erase), 1, 4 or 8");
        if (tool == "brush") {
            o.object({"tool", "samples", "radius", "points"});
            op.tool = render::SamplePaintOp::Tool::Brush;
            op.radius = o["radius"].number(NumberRule::closed(kMinSampleBrushRadius, kMaxSampleBrushRadius));
            for (const JsonField& pt : o["points"].items(1))
                op.points.push_back(pt.vec3());
        } else {
            o.object({"tool", "samples", "seed", "max_angle_deg"});
            op.tool = render::SamplePaintOp::Tool::Fill;
            op.points.push_back(o["seed"].vec3());
            op.maxAngleDeg = o.number("max_angle_deg", op.maxAngleDeg, NumberRule::closed(0.0, 180.0));
        }
        try {
            render::validateSamplePaintOp(op, o.origin() + ": " + o.path());
        } catch (const std::invalid_argument& e) {
            throw InputError(e.what());
        }
        ops.push_back(std::move(op));
    }
    return ops;
}

json lightSamplesJson(const std::vector<render::SamplePaintOp>& ops) {
    json out = json::array();
    for (const render::SamplePaintOp& op : ops) {
        if (op.tool == render::SamplePaintOp::Tool::Fill) {
            out.push_back({{"tool", "fill"},
                           {"samples", op.samples},
                           {"seed", vec3Json(op.points.front())},
                           {"max_angle_deg", op.maxAngleDeg}});
            continue;
        }
        json pts = json::array();
        for (const Eigen::Vector3d& pt : op.points)
            pts.push_back(vec3Json(pt));
        out.push_back({{"tool", "brush"}, {"samples", op.samples}, {"radius", op.radius}, {"points", pts}});
    }
    return out;
}

/// The interaction section (sim::readInteractionSection): every instrument's track is read from
/// a project file (kept in `trackFiles`), checked, and exported as tools/<instrument>.track.
sim::InteractionDesc readInteractionProject(const JsonField& section, const std::filesystem::path& dir,
                                            std::vector<std::filesystem::path>& trackFiles) {
    sim::InteractionDesc d = sim::readInteractionSection(section);
    trackFiles.clear();
    for (size_t i = 0; i < d.instruments.size(); ++i) {
        sim::InstrumentDesc& in = d.instruments[i];
        const std::filesystem::path file = dir / in.trackPath;
        if (const std::string why = outsideProjectProblem(dir, file); !why.empty())
            section.failAt("instruments[" + std::to_string(i) + "].track", why);
        in.trackText = readFile(file);
        sim::InstrumentTrack::parse(in.trackText, file.string()); // checked now, not in the player
        in.trackPath = "tools/" + in.name + ".track";
        trackFiles.push_back(file);
    }
    return d;
}

/// The scene's interaction section (sim::interactionJson) with the project's track files.
json interactionProjectJson(sim::InteractionDesc d, const std::vector<std::filesystem::path>& trackFiles,
                            const WriteContext& w) {
    if (trackFiles.size() != d.instruments.size())
        throw std::invalid_argument("studio::projectJsonText(): " + std::to_string(d.instruments.size()) +
                                    " instruments but " + std::to_string(trackFiles.size()) + " track files");
    for (size_t i = 0; i < d.instruments.size(); ++i)
        d.instruments[i].trackPath =
            projectFileJson(trackFiles[i], w, "interaction.instruments[" + std::to_string(i) + "].track");
    return sim::interactionJson(d);
}

} // namespace

Project loadProject(const std::filesystem::path& dir) {
    const std::filesystem::path file = dir / "project.json";
    return loadProjectText(readFile(file), dir, file.string());
}

std::vector<std::filesystem::path> projectInputFiles(const Project& p) {
    std::vector<std::filesystem::path> files{p.dir / "project.json"};
    auto texture = [&](const std::optional<TextureProject>& t) {
        if (t && t->generator.empty()) files.push_back(p.dir / t->spec);
    };
    for (const BodyProject& b : p.bodies) {
        if (b.mesh.kind == MeshSource::Kind::File) files.push_back(b.mesh.file);
        if (b.mesh.kind == MeshSource::Kind::Remesh) {
            for (const RemeshSource::Part& part : b.mesh.remesh.parts)
                files.push_back(part.file);
            if (!b.mesh.remesh.texture.empty()) files.push_back(b.mesh.remesh.texture);
        }
        texture(b.texture);
    }
    for (const SurfaceProject& s : p.surfaces)
        texture(s.texture);
    for (const auto& t : p.sceneryTextures)
        texture(t);
    if (!p.trajectory.file.empty()) files.push_back(p.trajectory.file);
    files.insert(files.end(), p.trackFiles.begin(), p.trackFiles.end());
    return files;
}

std::string placementProblem(const bake::ImportPlacement& placement, const std::string& field) {
    json block;
    writePlacement(placement, block);
    const std::string origin = "project.json";
    try {
        readPlacement(JsonField(block, field, origin));
    } catch (const InputError& e) {
        const std::string why = e.what();
        return why.rfind(origin + ": ", 0) == 0 ? why.substr(origin.size() + 2) : why;
    }
    return {};
}

Project loadProjectText(const std::string& text, const std::filesystem::path& dir, const std::string& origin) {
    const json doc = sim::parseJsonText(text, origin);
    const JsonField root(doc, "", origin);
    root.object({"schemaVersion", "caseId", "caseVersion", "title", "instructions", "steps", "solver", "gravity",
                 "bodies", "surfaces", "accuracy", "render", "suture", "interaction", "tools", "laparoscope", "bend",
                 "scenery", "assessment"});
    Project p;
    p.dir = dir;
    p.schemaVersion = root["schemaVersion"].integer(1, 1);
    p.caseId = vcase::readCaseId(root["caseId"]);
    p.caseVersion = vcase::readSemVer(root["caseVersion"]);
    if (auto v = root.find("title")) p.title = v->displayText(vcase::kMaxTitleBytes);

    // The scene part: the same readers as the player's scene.json.
    sim::SceneDesc& scene = p.scene;
    sim::readSolver(root, scene);
    if (auto su = root.find("suture")) scene.suture = readSutureProject(*su, dir, p.trajectory);
    if (auto v = root.find("instructions")) scene.instructions = v->displayText(sim::kMaxInstructionsBytes);
    if (auto v = root.find("steps")) scene.steps = sim::readSteps(*v);
    if (auto v = root.find("render")) {
        scene.render = v->anyObject().value().dump();
        render::RenderSettings check;
        render::applyCaseRender(check, scene.render, origin); // the player's rule for the block
        if (v->has("materials"))
            v->failAt("materials", "is written by export from the bodies' and surfaces' \"texture\" blocks; "
                                   "describe a material there");
    }
    scene.accuracy = sim::readAccuracy(root);

    std::set<std::string> names;
    // A project may have no body yet (File → New); export asks for one (requireABody).
    for (const JsonField& b : root["bodies"].items()) {
        b.object({"name", "mesh", "material", "strain_limits", "embedded_in", "embedding_compliance", "fixed",
                  "stiffness_regions", "stiffness_paint", "light_samples", "texture"});
        BodyProject body;
        sim::readBodyCommon(b, body.scene, names);
        body.mesh = readMeshSource(b["mesh"], dir);
        if (auto regions = b.find("stiffness_regions"))
            for (const JsonField& r : regions->items()) {
                r.object({"min", "max", "weight"});
                body.stiffnessRegions.push_back(
                    {r["min"].vec3(), r["max"].vec3(), r["weight"].number(NumberRule::positive())});
            }
        if (auto sp = b.find("stiffness_paint")) body.paint = readPaint(*sp, true);
        if (auto ls = b.find("light_samples")) body.lightSamples = readLightSamples(*ls);
        if (auto t = b.find("texture")) body.texture = readTexture(*t, dir);
        if (auto fx = b.find("fixed")) body.fixedBoxes = readHoldBoxes(*fx);
        p.bodies.push_back(std::move(body));
    }
    if (auto surfaces = root.find("surfaces"))
        for (const JsonField& sj : surfaces->items()) {
            sj.object({"name", "areal_density", "stretch_stiffness", "attach_distance", "attach_compliance",
                       "from_boundary_of", "region", "stiffness_paint", "texture", "subdivide"});
            SurfaceProject sp;
            sim::readSurfaceCommon(sj, sp.scene, names);
            const JsonField from = sj["from_boundary_of"];
            sp.scene.attachTo = from.string();
            bool found = false;
            for (const BodyProject& b : p.bodies)
                found |= b.scene.name == sp.scene.attachTo;
            if (!found) from.fail("'" + sp.scene.attachTo + "' is not a body");
            if (auto r = sj.find("region")) sp.region = readBox(*r);
            if (auto pt = sj.find("stiffness_paint")) sp.paint = readPaint(*pt, false);
            if (auto t = sj.find("texture")) sp.texture = readTexture(*t, dir);
            sp.subdivide = sj.integer("subdivide", 0, 0, 3);
            p.surfaces.push_back(std::move(sp));
        }
    if (auto t = root.find("tools")) scene.tools = sim::readTools(*t, names);
    if (auto l = root.find("laparoscope")) scene.laparoscope = sim::readLaparoscope(*l);
    if (auto a = root.find("assessment")) scene.assessment = sim::readAssessment(*a);
    if (auto b = root.find("bend")) p.bend = readBend(*b);
    if (auto sc = root.find("scenery")) {
        p.scenery = readSceneryProject(*sc, names, dir);
        const std::vector<JsonField> items = sc->items();
        p.sceneryTextures.resize(p.scenery.size());
        for (size_t k = 0; k < items.size() && k < p.scenery.size(); ++k)
            if (auto t = items[k].find("texture")) p.sceneryTextures[k] = readTexture(*t, dir);
    }
    if (auto in = root.find("interaction")) scene.interaction = readInteractionProject(*in, dir, p.trackFiles);
    // Cross-references (embedding cages, interaction names) are checked now, before any meshing.
    std::vector<const sim::BodyDesc*> bodies;
    for (const BodyProject& b : p.bodies)
        bodies.push_back(&b.scene);
    std::vector<const sim::SurfaceDesc*> surfaces;
    for (const SurfaceProject& s : p.surfaces)
        surfaces.push_back(&s.scene);
    sim::checkSceneReferences(bodies, surfaces, scene.interaction ? &*scene.interaction : nullptr, origin);
    std::vector<std::string> bodyNames;
    for (const BodyProject& b : p.bodies)
        bodyNames.push_back(b.scene.name);
    sim::checkAssessmentMeasurable(scene, bodyNames, origin);
    return p;
}

namespace {
std::atomic<uint64_t> g_projectTexts{0};
} // namespace

uint64_t projectTextCount() {
    return g_projectTexts.load();
}

std::string projectJsonText(const Project& p) {
    ++g_projectTexts;
    const WriteContext w{p.dir, (p.dir / "project.json").string()};
    const sim::SceneDesc& scene = p.scene;
    json doc = {{"schemaVersion", p.schemaVersion}, {"caseId", p.caseId}, {"caseVersion", p.caseVersion}};
    if (!p.title.empty()) doc["title"] = p.title;
    // The scene part: the same writers as the player's scene.json.
    sim::writeSolver(scene, doc);
    if (!scene.instructions.empty()) doc["instructions"] = scene.instructions;
    sim::writeSteps(scene.steps, doc);
    if (!scene.render.empty()) doc["render"] = json::parse(scene.render);
    sim::writeAccuracy(scene.accuracy, doc);
    if (scene.suture) doc["suture"] = sutureProjectJson(*scene.suture, p.trajectory, w);
    if (scene.interaction) doc["interaction"] = interactionProjectJson(*scene.interaction, p.trackFiles, w);
    sim::writeTools(scene.tools, doc);
    if (scene.laparoscope) sim::writeLaparoscope(*scene.laparoscope, doc);
    if (scene.assessment) sim::writeAssessment(*scene.assessment, doc);
    if (p.bend) doc["bend"] = bendJson(*p.bend);
    if (!p.scenery.empty()) {
        doc["scenery"] = sceneryJson(p.scenery, p.dir);
        for (size_t k = 0; k < p.scenery.size() && k < p.sceneryTextures.size(); ++k)
            if (p.sceneryTextures[k]) doc["scenery"][k]["texture"] = textureJson(*p.sceneryTextures[k]);
    }

    doc["bodies"] = json::array();
    for (size_t i = 0; i < p.bodies.size(); ++i) {
        const BodyProject& b = p.bodies[i];
        json j = {{"mesh", meshSourceJson(b.mesh, w, "bodies[" + std::to_string(i) + "].mesh")}};
        sim::writeBodyCommon(b.scene, j);
        if (b.fixedBoxes.size() == 1) j["fixed"] = boxJson(b.fixedBoxes.front());
        if (b.fixedBoxes.size() > 1) {
            j["fixed"] = json::array();
            for (const auto& box : b.fixedBoxes)
                j["fixed"].push_back(boxJson(box));
        }
        if (!b.stiffnessRegions.empty()) {
            json regions = json::array();
            for (const StiffnessRegion& r : b.stiffnessRegions)
                regions.push_back({{"min", vec3Json(r.min)}, {"max", vec3Json(r.max)}, {"weight", r.weight}});
            j["stiffness_regions"] = regions;
        }
        if (b.paint) j["stiffness_paint"] = paintJson(*b.paint, true);
        if (!b.lightSamples.empty()) j["light_samples"] = lightSamplesJson(b.lightSamples);
        if (b.texture) j["texture"] = textureJson(*b.texture);
        doc["bodies"].push_back(j);
    }
    if (!p.surfaces.empty()) {
        doc["surfaces"] = json::array();
        for (const SurfaceProject& s : p.surfaces) {
            json j = {{"from_boundary_of", s.scene.attachTo}};
            sim::writeSurfaceCommon(s.scene, j);
            if (s.region) j["region"] = boxJson(*s.region);
            if (s.paint) j["stiffness_paint"] = paintJson(*s.paint, false);
            if (s.texture) j["texture"] = textureJson(*s.texture);
            if (s.subdivide != 0) j["subdivide"] = s.subdivide;
            doc["surfaces"].push_back(j);
        }
    }
    return doc.dump(2) + "\n";
}

namespace {

/// Writes every instrument's track text (the model's) to its file, at the same place relative to
/// `dir` as to project.dir, atomically; a file that holds the text already is not rewritten.
void writeChangedTracks(const Project& project, const std::filesystem::path& dir) {
    namespace fs = std::filesystem;
    if (!project.scene.interaction) return;
    const std::vector<sim::InstrumentDesc>& list = project.scene.interaction->instruments;
    for (size_t i = 0; i < list.size() && i < project.trackFiles.size(); ++i) {
        const fs::path base = fs::absolute(project.dir.empty() ? fs::path(".") : project.dir).lexically_normal();
        const fs::path file = dir / fs::absolute(project.trackFiles[i]).lexically_normal().lexically_relative(base);
        std::error_code ec;
        if (fs::is_regular_file(file, ec)) {
            try {
                if (readFile(file) == list[i].trackText) continue;
            } catch (const InputError&) { // unreadable: written anew below (or the write says why)
            }
        }
        fs::create_directories(file.parent_path(), ec);
        writeFileAtomic(file, list[i].trackText);
    }
}

} // namespace

void saveProject(const Project& project, const std::filesystem::path& dir) {
    namespace fs = std::filesystem;
    const fs::path file = dir / "project.json";
    const std::string text = projectJsonText(project); // before touching the folder: a bad model writes nothing
    std::error_code ec;
    const fs::file_status st = fs::status(dir, ec);
    if (st.type() == fs::file_type::not_found)
        throw InputError(file.string() + ": cannot save: the folder '" + dir.string() + "' does not exist");
    if (!fs::is_directory(st))
        throw InputError(file.string() + ": cannot save: '" + dir.string() + "' is not a folder");
    if (::access(dir.c_str(), W_OK | X_OK) != 0)
        throw InputError(file.string() + ": cannot save: the folder is not writable (" + std::strerror(errno) + ")");
    writeChangedTracks(project, dir); // first: project.json never names a track that is not there
    writeFileAtomic(file, text);
}

sim::Material newBodyMaterial() {
    sim::Material m;
    m.model = sim::MaterialModel::StableNeoHookean;
    m.youngsModulus = 3000;
    m.poissonRatio = 0.45;
    m.density = 1050;
    return m;
}

Project newProject(const std::filesystem::path& dir, const std::string& caseId) {
    const std::string origin = (dir / "project.json").string();
    Project p;
    p.dir = dir;
    p.caseId = vcase::readCaseId(JsonField(json(caseId), "caseId", origin));
    p.caseVersion = "1.0.0";
    p.title = caseId;
    sim::SceneDesc& scene = p.scene;
    scene.solverType = "xpbd";
    scene.xpbd.dt = 1.0 / 60.0;
    scene.xpbd.substeps = 40; // the load-time stability check asks for at least 32 (E 3000 Pa, 5 mm cells)
    scene.xpbd.iterations = 1;
    scene.xpbd.damping = 2.0;
    scene.xpbd.gravity = sim::Vec3(0, 0, -9.81);
    return p;
}

void requireABody(const Project& project) {
    if (project.bodies.empty())
        throw InputError((project.dir / "project.json").string() +
                         ": bodies: a case needs at least one body; import anatomy or add a body");
}

namespace {

/// Tetrahedralize the block's surface (the kept one when Apply kept it: remesh_cache.hpp), the
/// boundary's corner UVs into `boundaryUv` (transferred from the UV surface, one host chart per
/// boundary triangle).
std::unique_ptr<sim::TetMesh> remeshBody(const RemeshSource& r, const bake::MeshingParams& meshing,
                                         std::vector<render::CornerUvF>* boundaryUv,
                                         const std::filesystem::path& projectDir, size_t& seededPoints) {
    RemeshedSurface s = keptOrFreshRemesh(r, projectDir);
    bake::MeshingParams smooth = meshing;
    smooth.featureAngleDeg = 0; // the voxel remesh rounded every edge: no feature to protect
    bake::TetrahedralizeResult meshed = bake::tetrahedralize(s.hull, smooth);
    seededPoints = meshed.report.missedSurfaceSeeds;
    std::unique_ptr<sim::TetMesh> mesh = std::move(meshed.mesh);
    if (!boundaryUv || s.uv.empty()) return mesh;
    const bake::UvSource remeshed({{"remeshed surface", std::move(s.surface), bake::CsgOp::Union, std::move(s.uv)}});
    auto probe = mesh->clone(); // the boundary in the render mesh's order
    probe->requireLevel(3);
    const std::vector<bake::CornerUv> corner =
        bake::transferUv(remeshed, probe->boundary(), bake::UvTransferMethod::SeamCutting);
    boundaryUv->clear();
    for (const bake::CornerUv& c : corner)
        boundaryUv->push_back({c[0].cast<float>(), c[1].cast<float>(), c[2].cast<float>()});
    return mesh;
}

} // namespace

std::unique_ptr<sim::TetMesh> buildBodyMesh(const BodyProject& body, const std::string& origin,
                                            std::vector<render::CornerUvF>* boundaryUv,
                                            const std::filesystem::path& projectDir, size_t* seededPoints) {
    const MeshSource& s = body.mesh;
    bake::MeshingParams params = s.meshing;
    params.label = origin + ": body '" + body.scene.name + "'";
    size_t seeded = 0;
    if (seededPoints) *seededPoints = 0;
    auto meshed = [&](const sim::TriMesh& surface) {
        bake::TetrahedralizeResult r = bake::tetrahedralize(surface, params);
        if (seededPoints) *seededPoints = r.report.missedSurfaceSeeds;
        return std::move(r.mesh);
    };
    switch (s.kind) {
    case MeshSource::Kind::Box:
        return sim::makeBoxTetMesh(s.box);
    case MeshSource::Kind::Ellipsoid:
        return meshed(sim::makeEllipsoidSurface(s.center, s.radii, s.slices, s.stacks));
    case MeshSource::Kind::Liver:
        return meshed(sim::makeLiverSurface(s.center, s.radii, s.wedge, s.slices, s.stacks));
    case MeshSource::Kind::Tube:
        return meshed(sim::makeTubeSurface(s.center, s.end, s.radius, s.slices, s.stacks));
    case MeshSource::Kind::HollowTube:
        return sim::makeHollowTubeTetMesh(s.hollow);
    case MeshSource::Kind::File: {
        if (sim::isTetFile(s.file)) return sim::readTetFile(s.file, s.scale); // tets as they are
        bake::ImportOptions opt;
        opt.scale = s.scale;
        params.label = s.file.filename().string();
        return meshed(bake::importSurface(s.file, opt));
    }
    case MeshSource::Kind::Remesh: {
        std::unique_ptr<sim::TetMesh> mesh = remeshBody(s.remesh, params, boundaryUv, projectDir, seeded);
        if (seededPoints) *seededPoints = seeded;
        return mesh;
    }
    }
    throw InputError(origin + ": unknown mesh source");
}

namespace {

bool inBox(const sim::Vec3& p, const sim::Vec3& lo, const sim::Vec3& hi) {
    return (p.array() >= lo.array()).all() && (p.array() <= hi.array()).all();
}

/// The triangles of `b` whose centroid lies in `region` (all when absent), as a surface with its
/// own compacted vertices.
sim::TriMesh cutRegion(const sim::TriMesh& b, const std::optional<std::array<sim::Vec3, 2>>& region) {
    std::vector<int32_t> remap(b.vertexCount(), sim::kNone);
    std::vector<sim::Vec3> pos;
    std::vector<sim::Tri> tris;
    for (const sim::Tri& t : b.triangles()) {
        const sim::Vec3 c = (b.positions()[t[0]] + b.positions()[t[1]] + b.positions()[t[2]]) / 3.0;
        if (region && !inBox(c, (*region)[0], (*region)[1])) continue;
        sim::Tri out;
        for (int k = 0; k < 3; ++k) {
            if (remap[t[k]] == sim::kNone) {
                remap[t[k]] = static_cast<int32_t>(pos.size());
                pos.push_back(b.positions()[t[k]]);
            }
            out[k] = remap[t[k]];
        }
        tris.push_back(out);
    }
    return sim::TriMesh::fromArrays(std::move(pos), std::move(tris), "fascia region");
}

/// A layer cut from the boundary of `mesh`: its triangles in `region`. Subdivided layers are cut
/// after subdividing, so their border follows the region in steps of the finer triangles.
sim::TriMesh cutBoundary(sim::TetMesh& mesh, const std::optional<std::array<sim::Vec3, 2>>& region, int subdivide) {
    mesh.requireLevel(3);
    if (subdivide == 0) return cutRegion(mesh.boundary(), region);
    return cutRegion(midpointSubdivide(mesh.boundary(), subdivide), region);
}

} // namespace

namespace {

/// Numbers the stages of an export for its progress callback.
struct StageCounter {
    const ExportProgress& progress;
    size_t total, done = 0;
    void operator()(const std::string& what) {
        ++done;
        if (progress) progress(done, total, what);
    }
};

} // namespace

bool usesPaintedSampling(const sim::SceneDesc& scene) {
    render::RenderSettings look;
    render::applyCaseRender(look, scene.render, "project.json"); // checked when the project was read
    return look.sampling.mode == render::SampleMode::Painted;
}

std::vector<double> bodyNodeWeights(const BodyProject& b, sim::TetMesh& mesh, std::optional<sim::Skeleton>& skeleton,
                                    const std::string& origin, const std::string& field) {
    const auto& pos = mesh.positions();
    std::vector<double> w;
    if (!b.stiffnessRegions.empty()) {
        w.assign(pos.size(), 1.0);
        for (size_t v = 0; v < pos.size(); ++v)
            for (const StiffnessRegion& r : b.stiffnessRegions)
                if (inBox(pos[v], r.min, r.max)) w[v] = r.weight;
    }
    if (!b.paint) return w;
    sim::StiffnessPaintResult paint;
    try {
        if (!skeleton) {
            bake::SkeletonParams skp = b.paint->skeleton;
            skp.label = origin + ": " + field + ".stiffness_paint.skeleton";
            skeleton = bake::extractSkeleton(mesh, skp).skeleton;
        }
        paint = sim::bakeStiffnessPaint(mesh, *skeleton, b.paint->strokes, b.paint->params);
    } catch (const std::invalid_argument& e) {
        throw InputError(origin + ": " + field + ".stiffness_paint: " + e.what());
    }
    if (w.empty()) return paint.weights;
    for (size_t v = 0; v < pos.size(); ++v)
        w[v] *= paint.weights[v];
    return w;
}

std::vector<double> surfaceNodeWeights(const SurfaceProject& s, const sim::TriMesh& mesh, const std::string& origin,
                                       const std::string& field) {
    if (!s.paint) return {};
    try {
        return sim::bakeSurfacePaint(mesh, s.paint->strokes, s.paint->params);
    } catch (const std::invalid_argument& e) {
        throw InputError(origin + ": " + field + ".stiffness_paint: " + e.what());
    }
}

std::string textureSpecText(const TextureProject& t, const std::filesystem::path& projectDir) {
    return t.generator.empty() ? readFile(projectDir / t.spec, std::uintmax_t{1} << 20) : t.generator;
}

bake::TextureSpec loadTextureBlock(const TextureProject& t, const std::filesystem::path& projectDir,
                                   const std::string& origin) {
    if (t.generator.empty()) return bake::loadTextureSpec(projectDir / t.spec);
    return bake::parseTextureSpec(t.generator, origin, projectDir);
}

TextureProject embedTextureSpec(const TextureProject& t, const std::filesystem::path& projectDir) {
    if (!t.generator.empty()) return t;
    const std::filesystem::path file = projectDir / t.spec;
    const std::string text = textureSpecText(t, projectDir);
    json doc = json::parse(text, nullptr, false);
    if (doc.is_discarded() || !doc.is_object()) throw InputError(file.string() + ": is not a JSON object");
    // The spec's file references are relative to its folder; in project.json they are relative
    // to the project folder.
    const std::filesystem::path folder = std::filesystem::path(t.spec).parent_path();
    auto rebase = [&](json& holder, const char* key) {
        if (holder.is_object() && holder.contains(key) && holder[key].is_string())
            holder[key] = (folder / holder[key].get<std::string>()).lexically_normal().generic_string();
    };
    auto rebaseSpec = [&](json& spec) {
        if (!spec.is_object()) return;
        if (spec.contains("patterns") && spec["patterns"].is_array())
            for (json& p : spec["patterns"])
                if (p.is_object() && p.contains("tile")) rebase(p["tile"], "file");
        if (spec.contains("palette")) rebase(spec["palette"], "image");
    };
    rebaseSpec(doc);
    if (doc.contains("layers") && doc["layers"].is_array())
        for (json& layer : doc["layers"])
            rebaseSpec(layer);
    if (const std::string stem = file.stem().string();
        !doc.contains("name") && !stem.empty() && !sim::entryNameProblem(stem))
        doc["name"] = stem; // the map files keep their names
    TextureProject out = t;
    out.spec.clear();
    out.generator = doc.dump();
    return out;
}

ProjectTextures bakeProjectTextures(const Project& project) {
    ProjectTextures out;
    const std::string origin = (project.dir / "project.json").string();
    auto bake = [&](const std::string& name, const TextureProject& t, const std::string& field) {
        const bake::TextureSpec spec = loadTextureBlock(t, project.dir, origin + ": " + field + ".texture.generator");
        const bake::TextureSet set = bake::generateTextureSet(spec);
        render::CaseMaterialMaps entry;
        entry.target = name;
        entry.tilesPerMetre = t.tilesPerMetre;
        entry.normalStrength = t.normalStrength;
        for (const bake::EncodedFile& f : bake::encodeTextureSet(spec, set)) {
            // only what the renderer samples is packaged
            for (const auto& [kind, slot] : {std::pair{bake::MapKind::Diffuse, &entry.diffuse},
                                             std::pair{bake::MapKind::Roughness, &entry.roughness},
                                             std::pair{bake::MapKind::Metallic, &entry.metallic},
                                             std::pair{bake::MapKind::Normal, &entry.normal}}) {
                const std::string suffix = "_" + std::string(bake::mapName(kind)) + ".png";
                if (f.fileName == spec.name + suffix) {
                    *slot = "textures/" + name + suffix;
                    out.files.emplace_back(*slot, f.bytes);
                }
            }
        }
        if (entry.files().empty())
            throw InputError(spec.origin + ": maps: writes none of diffuse, roughness, metallic, normal (nothing "
                                           "the renderer would sample)");
        out.materials.push_back(std::move(entry));
    };
    for (size_t i = 0; i < project.bodies.size(); ++i)
        if (const BodyProject& b = project.bodies[i]; b.texture)
            bake(b.scene.name, *b.texture, "bodies[" + std::to_string(i) + "]");
    for (size_t i = 0; i < project.surfaces.size(); ++i)
        if (const SurfaceProject& s = project.surfaces[i]; s.texture)
            bake(s.scene.name, *s.texture, "surfaces[" + std::to_string(i) + "]");
    for (size_t k = 0; k < project.scenery.size() && k < project.sceneryTextures.size(); ++k)
        if (project.sceneryTextures[k])
            bake(project.scenery[k].name, *project.sceneryTextures[k], "scenery[" + std::to_string(k) + "]");
    return out;
}

std::string renderWithMaterials(const std::string& render, const std::vector<render::CaseMaterialMaps>& materials) {
    if (materials.empty()) return render;
    json doc = render.empty() ? json::object() : json::parse(render);
    json& m = doc["materials"] = json::object();
    for (const render::CaseMaterialMaps& e : materials) {
        json j = {{"tiles_per_metre", e.tilesPerMetre}, {"normal_strength", e.normalStrength}};
        for (const auto& [key, path] :
             {std::pair{"diffuse", &e.diffuse}, std::pair{"roughness", &e.roughness},
              std::pair{"metallic", &e.metallic}, std::pair{"normal", &e.normal}, std::pair{"uv", &e.uv}})
            if (!path->empty()) j[key] = *path;
        m[e.target] = std::move(j);
    }
    return doc.dump();
}

namespace {

/// A remeshed body with UVs: its corner UVs, and the remesh block's texture as its diffuse map
/// (only when something is laid by them: that texture, or the body's texture block).
void addUvMaterial(BuiltScene& built, const BodyProject& b, const std::vector<render::CornerUvF>& uv,
                   const std::string& origin, const std::string& field) {
    const std::string& name = b.scene.name;
    const std::filesystem::path& texture = b.mesh.remesh.texture;
    if (texture.empty() && !b.texture) return;
    if (!texture.empty() && b.texture)
        throw InputError(origin + ": " + field +
                         ".mesh.remesh.texture: the body has a texture block too (give one of them)");
    render::CaseMaterialMaps m;
    m.target = name;
    m.uv = "meshes/" + name + ".vuv";
    built.files.emplace_back(m.uv, render::cornerUvBytes(uv));
    if (!texture.empty()) {
        m.diffuse = "textures/" + name + "_diffuse.png";
        std::string bytes = readFile(texture, 64u << 20);
        const auto read = [&](const std::string&) { return std::string_view(bytes); };
        render::loadMaterialMaps(m, read, texture.string()); // a PNG the player can decode, or refused here
        built.files.emplace_back(m.diffuse, std::move(bytes));
    }
    built.materials.push_back(std::move(m));
}

/// The anatomy made by code, after every body and surface was generated, fixed and painted flat:
/// the bend (bodies and surfaces), then the mesh files; the scenery surfaces and their files.
void shapeAndWriteMeshes(const Project& project, BuiltScene& built, const std::string& origin) {
    if (project.bend) {
        for (const auto& m : built.meshes)
            built.flatMeshes.push_back(sim::TetMesh::fromArrays(m->positions(), m->tets(), "flat"));
        built.flatSurfaces = built.surfaces;
        try {
            for (size_t i = 0; i < built.meshes.size(); ++i) {
                std::vector<sim::Vec3> pos = built.meshes[i]->positions();
                bendPoints(*project.bend, pos);
                built.meshes[i] = sim::TetMesh::fromArrays(std::move(pos), built.meshes[i]->tets(), "bend");
            }
            for (sim::TriMesh& s : built.surfaces) {
                std::vector<sim::Vec3> pos = s.positions();
                bendPoints(*project.bend, pos);
                s = sim::TriMesh::fromArrays(std::move(pos), s.triangles(), "bend");
            }
        } catch (const std::invalid_argument& e) {
            throw InputError(origin + ": bend.radius: " + e.what());
        }
    }
    for (auto& m : built.meshes) // the world's collision surfaces read the boundary (the player's loader has it)
        m->requireLevel(3);
    for (size_t i = 0; i < built.meshes.size(); ++i)
        built.files.emplace_back(built.scene.bodies[i].meshPath, sim::formatVtet(*built.meshes[i]));
    for (size_t s = 0; s < built.surfaces.size(); ++s)
        built.files.emplace_back(built.scene.surfaces[s].meshPath, sim::formatVtri(built.surfaces[s]));
    for (const SceneryProject& sp : project.scenery) {
        sim::SceneryDesc d{sp.name, "meshes/" + sp.name + ".vtri"};
        built.files.emplace_back(d.meshPath, sim::formatVtri(scenerySurface(sp)));
        built.scene.scenery.push_back(std::move(d));
    }
}

BuiltScene buildSceneCounted(const Project& project, StageCounter& stage) {
    requireABody(project);
    const std::string origin = (project.dir / "project.json").string();
    BuiltScene built;
    built.scene = project.scene; // what the player reads; the bodies follow with their meshes
    sim::SceneDesc& scene = built.scene;
    ExportResult& result = built.result;
    auto& files = built.files;
    auto& meshes = built.meshes;
    auto& surfaces = built.surfaces;
    const bool paintedSampling = usesPaintedSampling(project.scene);
    for (size_t i = 0; i < project.bodies.size(); ++i) {
        const BodyProject& b = project.bodies[i];
        const std::string& name = b.scene.name;
        const std::string field = "bodies[" + std::to_string(i) + "] ('" + name + "')";
        stage("meshing body '" + name + "'");
        std::unique_ptr<sim::TetMesh> mesh;
        std::vector<render::CornerUvF> boundaryUv;
        try {
            mesh = buildBodyMesh(b, origin, &boundaryUv, project.dir);
        } catch (const std::invalid_argument& e) {
            throw InputError(origin + ": " + field + ".mesh: " + e.what());
        }
        try {
            if (!boundaryUv.empty()) addUvMaterial(built, b, boundaryUv, origin, field);
        } catch (const std::invalid_argument& e) { // a UV beyond the corner-UV file's range
            throw InputError(origin + ": " + field + ".mesh.remesh: " + e.what());
        }
        sim::BodyDesc desc = b.scene;
        desc.meshPath = "meshes/" + name + ".vtet";
        BodyExport be = checkBodyMesh(b, *mesh, desc, origin, field);
        if (b.paint) stage("skeleton and stiffness paint of '" + name + "'");
        std::optional<sim::Skeleton> skeleton;
        desc.nodeWeights = bodyNodeWeights(b, *mesh, skeleton, origin, field);
        if (b.paint) {
            desc.nodeWeightsPath = "meshes/" + name + ".vweights";
            files.emplace_back(desc.nodeWeightsPath, sim::formatNodeWeights(desc.nodeWeights));
        }
        if (paintedSampling && !b.lightSamples.empty()) { // packaged only where the look uses it
            render::RenderMesh surface = render::bodySurfaceMesh(*mesh, name, i);
            try {
                render::applySamplePaint(surface, b.lightSamples);
            } catch (const std::invalid_argument& e) {
                throw InputError(origin + ": " + field + ".light_samples: " + e.what());
            }
            desc.sampleMapPath = "maps/" + name + ".vsamples";
            files.emplace_back(desc.sampleMapPath,
                               render::formatSampleMap(render::nodeSampleClasses(surface, mesh->vertexCount())));
        }
        built.skeletons.push_back(std::move(skeleton));
        scene.bodies.push_back(std::move(desc)); // its mesh file once shaped (shapeAndWriteMeshes)
        result.bodies.push_back(std::move(be));
        meshes.push_back(std::move(mesh));
    }
    for (size_t s = 0; s < project.surfaces.size(); ++s) {
        const SurfaceProject& sp = project.surfaces[s];
        const std::string& from = sp.scene.attachTo;
        stage("cutting surface '" + sp.scene.name + "'");
        size_t body = 0;
        while (project.bodies[body].scene.name != from)
            ++body;
        sim::TriMesh tri;
        try {
            tri = cutBoundary(*meshes[body], sp.region, sp.subdivide);
        } catch (const std::invalid_argument&) {
            throw InputError(origin + ": surfaces[" + std::to_string(s) +
                             "].region: contains no boundary triangle of '" + from + "'");
        }
        sim::SurfaceDesc sd = sp.scene;
        sd.meshPath = "meshes/" + sd.name + ".vtri";
        if (sp.paint) {
            sd.nodeWeights = surfaceNodeWeights(sp, tri, origin, "surfaces[" + std::to_string(s) + "]");
            sd.nodeWeightsPath = "meshes/" + sd.name + ".vweights";
            files.emplace_back(sd.nodeWeightsPath, sim::formatNodeWeights(sd.nodeWeights));
        }
        scene.surfaces.push_back(std::move(sd));
        surfaces.push_back(std::move(tri));
    }
    shapeAndWriteMeshes(project, built, origin);
    built.features = sim::requiredFeatures(scene); // only what the scene needs
    return built;
}

} // namespace

bool hasTextures(const Project& project) {
    for (const BodyProject& b : project.bodies)
        if (b.texture) return true;
    for (const SurfaceProject& s : project.surfaces)
        if (s.texture) return true;
    for (const auto& t : project.sceneryTextures)
        if (t) return true;
    return false;
}

size_t exportStageCount(const Project& project) {
    size_t n = project.bodies.size() + project.surfaces.size() + 2; // + checking the scene, packaging
    for (const BodyProject& b : project.bodies)
        n += b.paint ? 1 : 0;
    return n + (hasTextures(project) ? 1 : 0);
}

BodyExport checkBodyMesh(const BodyProject& b, const sim::TetMesh& mesh, sim::BodyDesc& desc, const std::string& origin,
                         const std::string& field) {
    BodyExport be;
    be.name = b.scene.name;
    be.nodes = mesh.vertexCount();
    be.tets = mesh.tetCount();
    be.quality = mesh.quality();
    if (!be.quality.inverted.empty())
        throw InputError(origin + ": " + field + ".mesh: tet " + std::to_string(be.quality.inverted.front()) +
                         " is inverted (" + std::to_string(be.quality.inverted.size()) + " inverted in all)");
    if (!be.quality.degenerate.empty())
        throw InputError(origin + ": " + field + ".mesh: tet " + std::to_string(be.quality.degenerate.front()) +
                         " is degenerate (" + std::to_string(be.quality.degenerate.size()) + " in all)");
    const std::vector<int32_t> held = heldNodes(b, mesh, origin, field);
    desc.fixedNodes.insert(desc.fixedNodes.end(), held.begin(), held.end());
    be.fixedNodes = desc.fixedNodes.size();
    return be;
}

std::vector<int32_t> heldNodes(const BodyProject& b, const sim::TetMesh& mesh, const std::string& origin,
                               const std::string& field) {
    const auto& pos = mesh.positions();
    std::vector<bool> held(pos.size(), false);
    for (size_t k = 0; k < b.fixedBoxes.size(); ++k) {
        const auto& box = b.fixedBoxes[k];
        bool any = false;
        for (size_t v = 0; v < pos.size(); ++v)
            if (inBox(pos[v], box[0], box[1])) held[v] = any = true;
        if (!any)
            throw InputError(origin + ": " + field + ".fixed" +
                             (b.fixedBoxes.size() > 1 ? "[" + std::to_string(k) + "]" : std::string()) +
                             ": the box contains no mesh node");
    }
    std::vector<int32_t> nodes;
    for (int32_t v = 0; v < static_cast<int32_t>(pos.size()); ++v)
        if (held[static_cast<size_t>(v)]) nodes.push_back(v);
    return nodes;
}

BuiltScene buildScene(const Project& project, const ExportProgress& progress) {
    StageCounter stage{progress, exportStageCount(project) - 2 - (hasTextures(project) ? 1 : 0)};
    return buildSceneCounted(project, stage);
}

std::unique_ptr<sim::World> assembleWorld(const BuiltScene& built, const std::string& origin) {
    std::vector<std::unique_ptr<sim::TetMesh>> meshes;
    for (const auto& m : built.meshes) {
        meshes.push_back(m->clone());
        meshes.back()->requireLevel(3);
    }
    return sim::World::assemble(built.scene, std::move(meshes), built.surfaces, built.features, origin);
}

std::vector<std::string> reachWarnings(const Project& project) {
    std::vector<std::string> out;
    const std::string origin = (project.dir / "project.json").string();
    for (const sim::ReachProblem& r : sim::unreachableTargets(project.scene))
        out.push_back(origin + ": " + r.message);
    return out;
}

ExportResult exportCase(const Project& project, const std::filesystem::path& out, const ExportProgress& progress,
                        const CasePublishing& publish) {
    // Before the work: the case can be written, and over none of the files it is made from.
    requireWritableFile(out, "the case");
    requireNotAnInput(out, "the case", projectInputFiles(project));
    requireABody(project); // before the material maps are baked
    const std::string origin = (project.dir / "project.json").string();
    std::vector<std::string> bodyNames;
    for (const BodyProject& b : project.bodies)
        bodyNames.push_back(b.scene.name);
    sim::checkAssessmentMeasurable(project.scene, bodyNames, origin); // every metric it cannot measure, at once
    StageCounter stage{progress, exportStageCount(project)};
    ProjectTextures textures; // first: a broken spec is reported before the meshing
    if (hasTextures(project)) {
        stage("generating material maps");
        textures = bakeProjectTextures(project);
    }
    BuiltScene built = buildSceneCounted(project, stage);
    // The player runs what it loads, so assemble the world here exactly as the player will and
    // refuse a case that cannot be simulated stably.
    stage("checking the scene");
    sim::World::assemble(built.scene, std::move(built.meshes), std::move(built.surfaces), built.features, origin);
    const sim::SceneDesc& scene = built.scene;
    const std::vector<std::string>& features = built.features;
    ExportResult result = std::move(built.result);
    result.warnings = reachWarnings(project);
    auto& files = built.files;

    stage("packaging");
    vcase::Manifest header;
    header.caseId = project.caseId;
    header.caseVersion = project.caseVersion;
    header.minPlayerVersion = VISCERA_VERSION;
    if (!project.title.empty()) header.title = project.title;
    header.expires = publish.expires;
    header.features = features;
    vcase::CaseWriter writer(header);
    if (publish.key) writer.sign(*publish.key, publish.signer);
    for (const render::CaseMaterialMaps& m : built.materials) { // a texture block laid by UVs, or the remesh texture
        auto it = std::find_if(textures.materials.begin(), textures.materials.end(),
                               [&](const render::CaseMaterialMaps& t) { return t.target == m.target; });
        if (it != textures.materials.end())
            it->uv = m.uv;
        else
            textures.materials.push_back(m);
    }
    sim::SceneDesc written = scene;
    written.render = renderWithMaterials(scene.render, textures.materials);
    writer.addFile("scene.json", sim::formatScene(written));
    // The package holds exactly the files the scene names (render::caseFileReferences, the table
    // the player's load checks), each made by one of the stages above.
    std::map<std::string, std::string> made;
    for (auto& [path, bytes] : files)
        made[path] = std::move(bytes);
    for (auto& [path, bytes] : textures.files)
        made[path] = std::move(bytes);
    if (scene.suture) made[scene.suture->trajectoryPath] = scene.suture->trajectoryText;
    if (scene.interaction)
        for (const sim::InstrumentDesc& in : scene.interaction->instruments)
            made[in.trackPath] = in.trackText;
    for (const render::CaseFileRef& ref :
         render::caseFileReferences(written, render::caseMaterialMaps(written.render, origin))) {
        auto it = made.find(ref.path);
        if (it == made.end())
            throw std::logic_error("studio::exportCase(): " + ref.field + " names '" + ref.path +
                                   "', which no export stage made");
        writer.addFile(ref.path, std::move(it->second));
        made.erase(it);
    }
    if (!made.empty())
        throw std::logic_error("studio::exportCase(): '" + made.begin()->first +
                               "' was made but the scene does not name it");
    const vcase::Manifest manifest = writer.write(out, {}, &result.sha256);
    result.casePath = out;
    result.features = manifest.features;
    result.bytes = std::filesystem::file_size(out);
    if (publish.key) result.keyId = vcase::keyId(publish.key->publicKey());
    return result;
}

std::filesystem::path projectFileOf(const JsonField& f, const std::filesystem::path& dir) {
    return projectFile(f, dir);
}

std::string projectRelativePath(const std::filesystem::path& file, const std::filesystem::path& dir,
                                const std::string& where) {
    namespace fs = std::filesystem;
    const fs::path base = fs::absolute(dir.empty() ? fs::path(".") : dir).lexically_normal();
    const std::string rel = fs::absolute(file).lexically_normal().lexically_relative(base).generic_string();
    if (rel.empty() || sim::entryNameProblem(rel))
        throw InputError(where + ": '" + file.string() + "' is not inside the project folder '" + dir.string() + "'");
    return rel;
}

} // namespace viscera::studio
