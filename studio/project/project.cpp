#include "project/project.hpp"

#include "render/case_settings.hpp"

#include "bake/import.hpp"
#include "case/case_writer.hpp"
#include "sim/mesh/tet_io.hpp"
#include "sim/scene/material_json.hpp"
#include "sim/scene/scene.hpp"
#include "sim/scene/world.hpp"
#include "sim/skeleton/node_weights_io.hpp"
#include "sim/suture/anastomosis.hpp"
#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"

#include <algorithm>
#include <cctype>
#include <nlohmann/json.hpp>

#include <cmath>
#include <set>

namespace viscera::studio {
namespace {

using nlohmann::json;

/// Strict field access with messages naming the file and the field path.
class Fields {
public:
    explicit Fields(std::string origin) : m_origin(std::move(origin)) {}
    [[noreturn]] void fail(const std::string& field, const std::string& rule) const {
        throw InputError(m_origin + ": " + field + ": " + rule);
    }
    const json& req(const json& obj, const std::string& key, const std::string& path) const {
        const std::string field = path.empty() ? key : path + "." + key;
        if (!obj.is_object()) fail(path.empty() ? "(root)" : path, "must be an object");
        auto it = obj.find(key);
        if (it == obj.end()) fail(field, "required field is missing");
        return *it;
    }
    const json* opt(const json& obj, const std::string& key) const {
        auto it = obj.find(key);
        return it == obj.end() ? nullptr : &*it;
    }
    double num(const json& v, const std::string& field) const {
        if (!v.is_number() || !std::isfinite(v.get<double>())) fail(field, "must be a finite number");
        return v.get<double>();
    }
    double positive(const json& v, const std::string& field) const {
        double d = num(v, field);
        if (!(d > 0)) fail(field, "must be positive");
        return d;
    }
    int integer(const json& v, const std::string& field, int lo, int hi) const {
        if (!v.is_number_integer()) fail(field, "must be an integer");
        auto i = v.get<int64_t>();
        if (i < lo || i > hi) fail(field, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
        return static_cast<int>(i);
    }
    std::string str(const json& v, const std::string& field) const {
        if (!v.is_string()) fail(field, "must be a string");
        return v.get<std::string>();
    }
    sim::Vec3 vec3(const json& v, const std::string& field) const {
        if (!v.is_array() || v.size() != 3) fail(field, "must be an array of 3 numbers");
        return {num(v[0], field + "[0]"), num(v[1], field + "[1]"), num(v[2], field + "[2]")};
    }
    void only(const json& obj, std::initializer_list<const char*> keys, const std::string& path) const {
        for (auto it = obj.begin(); it != obj.end(); ++it) {
            bool known = false;
            for (const char* k : keys) known |= it.key() == k;
            if (!known) fail(path.empty() ? it.key() : path + "." + it.key(), "unknown field");
        }
    }

private:
    std::string m_origin;
};

bake::MeshingParams parseMeshing(const Fields& f, const json* m, const std::string& path) {
    bake::MeshingParams p;
    if (!m) return p;
    if (!m->is_object()) f.fail(path, "must be an object");
    f.only(*m, {"facet_angle", "facet_size", "facet_distance", "cell_radius_edge_ratio", "cell_size", "seed"}, path);
    if (auto* v = f.opt(*m, "facet_angle")) p.facetAngleDeg = f.positive(*v, path + ".facet_angle");
    if (auto* v = f.opt(*m, "facet_size")) p.facetSize = f.positive(*v, path + ".facet_size");
    if (auto* v = f.opt(*m, "facet_distance")) p.facetDistance = f.positive(*v, path + ".facet_distance");
    if (auto* v = f.opt(*m, "cell_radius_edge_ratio"))
        p.cellRadiusEdgeRatio = f.positive(*v, path + ".cell_radius_edge_ratio");
    if (auto* v = f.opt(*m, "cell_size")) p.cellSize = f.positive(*v, path + ".cell_size");
    if (auto* v = f.opt(*m, "seed")) p.seed = static_cast<unsigned>(f.integer(*v, path + ".seed", 0, 1 << 30));
    return p;
}

MeshSource parseMeshSource(const Fields& f, const json& m, const std::string& path,
                           const std::filesystem::path& dir) {
    MeshSource s;
    if (!m.is_object()) f.fail(path, "must be an object");
    if (auto* file = f.opt(m, "file")) {
        f.only(m, {"file", "scale", "meshing"}, path);
        s.kind = MeshSource::Kind::File;
        const std::string rel = f.str(*file, path + ".file");
        std::filesystem::path p(rel);
        if (p.is_absolute() || rel.find("..") != std::string::npos)
            f.fail(path + ".file", "must be a path inside the project folder");
        s.file = dir / p;
        if (auto* v = f.opt(m, "scale")) s.scale = f.positive(*v, path + ".scale");
        s.meshing = parseMeshing(f, f.opt(m, "meshing"), path + ".meshing");
        return s;
    }
    const std::string gen = f.str(f.req(m, "generator", path), path + ".generator");
    if (gen == "box") {
        f.only(m, {"generator", "origin", "size", "cells"}, path);
        s.kind = MeshSource::Kind::Box;
        if (auto* v = f.opt(m, "origin")) s.box.origin = f.vec3(*v, path + ".origin");
        s.box.size = f.vec3(f.req(m, "size", path), path + ".size");
        if (!(s.box.size.array() > 0).all()) f.fail(path + ".size", "every edge length must be positive");
        const json& c = f.req(m, "cells", path);
        if (!c.is_array() || c.size() != 3) f.fail(path + ".cells", "must be an array of 3 integers");
        for (int k = 0; k < 3; ++k)
            s.box.cells[k] = f.integer(c[k], path + ".cells[" + std::to_string(k) + "]", 1, 512);
    } else if (gen == "ellipsoid") {
        f.only(m, {"generator", "center", "radii", "slices", "stacks", "meshing"}, path);
        s.kind = MeshSource::Kind::Ellipsoid;
        if (auto* v = f.opt(m, "center")) s.center = f.vec3(*v, path + ".center");
        s.radii = f.vec3(f.req(m, "radii", path), path + ".radii");
        if (!(s.radii.array() > 0).all()) f.fail(path + ".radii", "every radius must be positive");
        if (auto* v = f.opt(m, "slices")) s.slices = f.integer(*v, path + ".slices", 3, 1024);
        if (auto* v = f.opt(m, "stacks")) s.stacks = f.integer(*v, path + ".stacks", 2, 1024);
        s.meshing = parseMeshing(f, f.opt(m, "meshing"), path + ".meshing");
    } else if (gen == "liver") {
        f.only(m, {"generator", "center", "half_size", "wedge", "slices", "stacks", "meshing"}, path);
        s.kind = MeshSource::Kind::Liver;
        if (auto* v = f.opt(m, "center")) s.center = f.vec3(*v, path + ".center");
        s.radii = f.vec3(f.req(m, "half_size", path), path + ".half_size");
        if (!(s.radii.array() > 0).all()) f.fail(path + ".half_size", "every half size must be positive");
        if (auto* v = f.opt(m, "wedge")) s.wedge = f.positive(*v, path + ".wedge");
        if (s.wedge > 1) f.fail(path + ".wedge", "must be in (0, 1]");
        if (auto* v = f.opt(m, "slices")) s.slices = f.integer(*v, path + ".slices", 3, 1024);
        if (auto* v = f.opt(m, "stacks")) s.stacks = f.integer(*v, path + ".stacks", 2, 1024);
        s.meshing = parseMeshing(f, f.opt(m, "meshing"), path + ".meshing");
    } else if (gen == "tube") {
        f.only(m, {"generator", "start", "end", "radius", "slices", "rings", "meshing"}, path);
        s.kind = MeshSource::Kind::Tube;
        s.center = f.vec3(f.req(m, "start", path), path + ".start");
        s.end = f.vec3(f.req(m, "end", path), path + ".end");
        s.radius = f.positive(f.req(m, "radius", path), path + ".radius");
        if ((s.end - s.center).norm() <= 0) f.fail(path + ".end", "must differ from start");
        if (auto* v = f.opt(m, "slices")) s.slices = f.integer(*v, path + ".slices", 3, 1024);
        if (auto* v = f.opt(m, "rings")) s.stacks = f.integer(*v, path + ".rings", 1, 1024);
        s.meshing = parseMeshing(f, f.opt(m, "meshing"), path + ".meshing");
    } else if (gen == "hollow_tube") {
        f.only(m, {"generator", "start", "end", "inner_radius", "outer_radius", "slices", "layers", "rings"}, path);
        s.kind = MeshSource::Kind::HollowTube;
        s.hollow.start = f.vec3(f.req(m, "start", path), path + ".start");
        s.hollow.end = f.vec3(f.req(m, "end", path), path + ".end");
        if ((s.hollow.end - s.hollow.start).norm() <= 0) f.fail(path + ".end", "must differ from start");
        s.hollow.innerRadius = f.positive(f.req(m, "inner_radius", path), path + ".inner_radius");
        s.hollow.outerRadius = f.positive(f.req(m, "outer_radius", path), path + ".outer_radius");
        if (!(s.hollow.outerRadius > s.hollow.innerRadius)) f.fail(path + ".outer_radius", "must exceed inner_radius");
        if (auto* v = f.opt(m, "slices")) s.hollow.slices = f.integer(*v, path + ".slices", 3, 1024);
        if (auto* v = f.opt(m, "layers")) s.hollow.layers = f.integer(*v, path + ".layers", 1, 64);
        if (auto* v = f.opt(m, "rings")) s.hollow.rings = f.integer(*v, path + ".rings", 1, 1024);
    } else {
        f.fail(path + ".generator", "'" + gen + "' is not a known generator (box, ellipsoid, liver, tube, hollow_tube)");
    }
    return s;
}

/// The suture section: the trajectory is generated (anastomosis) or read from a project file,
/// checked, and referenced as tools/needle.traj in the exported scene.
sim::suture::SutureSceneDesc parseSutureProject(const Fields& f, const json& su, const std::filesystem::path& dir,
                                                const std::string& origin) {
    if (!su.is_object()) f.fail("suture", "must be an object");
    const json& t = f.req(su, "trajectory", "suture");
    if (!t.is_object()) f.fail("suture.trajectory", "must be an object with 'generator' or 'file'");
    std::string text;
    if (auto* file = f.opt(t, "file")) {
        f.only(t, {"file"}, "suture.trajectory");
        const std::string rel = f.str(*file, "suture.trajectory.file");
        if (std::filesystem::path(rel).is_absolute() || rel.find("..") != std::string::npos)
            f.fail("suture.trajectory.file", "must be a path inside the project folder");
        text = readFile(dir / rel);
        sim::suture::parseTrajectory(text, (dir / rel).string()); // checked now, not in the player
    } else {
        const std::string p = "suture.trajectory";
        const std::string gen = f.str(f.req(t, "generator", p), p + ".generator");
        if (gen != "anastomosis") f.fail(p + ".generator", "'" + gen + "' is not a known generator (anastomosis)");
        f.only(t, {"generator", "stitches", "needle_radius", "needle_centre", "degrees_per_frame", "transfer_frames",
                   "transfer_distance", "pull_frames", "pull_per_segment", "slack"},
               p);
        sim::suture::AnastomosisSpec a;
        if (auto* v = f.opt(t, "stitches")) a.stitches = f.integer(*v, p + ".stitches", 1, 64);
        if (auto* v = f.opt(t, "needle_radius")) a.needleRadius = f.positive(*v, p + ".needle_radius");
        if (auto* v = f.opt(t, "needle_centre")) a.needleCentre = f.positive(*v, p + ".needle_centre");
        if (auto* v = f.opt(t, "degrees_per_frame")) a.degreesPerFrame = f.positive(*v, p + ".degrees_per_frame");
        if (auto* v = f.opt(t, "transfer_frames")) a.transferFrames = f.integer(*v, p + ".transfer_frames", 1, 10000);
        if (auto* v = f.opt(t, "transfer_distance")) a.transferDistance = f.positive(*v, p + ".transfer_distance");
        if (auto* v = f.opt(t, "pull_frames")) a.pullFrames = f.integer(*v, p + ".pull_frames", 1, 100000);
        if (auto* v = f.opt(t, "pull_per_segment")) a.pullPerSegment = f.positive(*v, p + ".pull_per_segment");
        if (auto* v = f.opt(t, "slack")) a.slack = f.num(*v, p + ".slack");
        if (a.degreesPerFrame > 90) f.fail(p + ".degrees_per_frame", "must be at most 90");
        text = sim::suture::formatTrajectory(sim::suture::makeAnastomosisTrajectory(a));
    }
    json section = su;
    section["trajectory"] = "tools/needle.traj";
    sim::suture::SutureSceneDesc d = sim::suture::parseSutureSection(section.dump(), origin);
    d.trajectoryText = std::move(text);
    return d;
}

StiffnessPaintProject parsePaint(const Fields& f, const json& j, const std::string& path, const std::string& origin) {
    f.only(j, {"skeleton", "base_weight", "min_weight", "max_weight", "strokes"}, path);
    StiffnessPaintProject p;
    if (auto* sk = f.opt(j, "skeleton")) {
        f.only(*sk, {"min_edge_length_rel", "medially_centered", "max_iterations"}, path + ".skeleton");
        if (auto* v = f.opt(*sk, "min_edge_length_rel")) p.skeleton.minEdgeLengthRel = f.positive(*v, path + ".skeleton.min_edge_length_rel");
        if (auto* v = f.opt(*sk, "medially_centered")) {
            if (!v->is_boolean()) f.fail(path + ".skeleton.medially_centered", "must be true or false");
            p.skeleton.mediallyCentered = v->get<bool>();
        }
        if (auto* v = f.opt(*sk, "max_iterations"))
            p.skeleton.maxIterations = static_cast<size_t>(f.integer(*v, path + ".skeleton.max_iterations", 1, 10000));
    }
    if (auto* v = f.opt(j, "base_weight")) p.params.baseWeight = f.positive(*v, path + ".base_weight");
    if (auto* v = f.opt(j, "min_weight")) p.params.minWeight = f.positive(*v, path + ".min_weight");
    if (auto* v = f.opt(j, "max_weight")) p.params.maxWeight = f.positive(*v, path + ".max_weight");
    p.params.origin = origin + ": " + path;
    const json& strokes = f.req(j, "strokes", path);
    if (!strokes.is_array() || strokes.empty()) f.fail(path + ".strokes", "must be a non-empty array");
    for (size_t k = 0; k < strokes.size(); ++k) {
        const std::string sp = path + ".strokes[" + std::to_string(k) + "]";
        f.only(strokes[k], {"center", "radius", "amplitude", "scale"}, sp);
        sim::BrushStroke s;
        s.center = f.vec3(f.req(strokes[k], "center", sp), sp + ".center");
        s.radius = f.positive(f.req(strokes[k], "radius", sp), sp + ".radius");
        s.amplitude = f.num(f.req(strokes[k], "amplitude", sp), sp + ".amplitude");
        if (auto* v = f.opt(strokes[k], "scale")) {
            const std::string sc = f.str(*v, sp + ".scale");
            if (sc == "peak") s.scale = sim::BrushScale::Peak;
            else if (sc == "kernel") s.scale = sim::BrushScale::Kernel;
            else f.fail(sp + ".scale", "'" + sc + "' is not a brush scale (peak, kernel)");
        }
        try {
            sim::validateStroke(s, k, origin + ": " + sp);
        } catch (const std::exception& e) {
            throw InputError(e.what());
        }
        p.strokes.push_back(s);
    }
    return p;
}

/// The interaction section: every instrument's track is read from a project file, checked, and
/// exported as tools/<instrument>.track.
sim::InteractionDesc parseInteractionProject(const Fields& f, const json& section, const std::filesystem::path& dir,
                                             const std::string& origin) {
    if (!section.is_object()) f.fail("interaction", "must be an object");
    sim::InteractionDesc d = sim::parseInteractionSection(section.dump(), origin);
    for (size_t i = 0; i < d.instruments.size(); ++i) {
        sim::InstrumentDesc& in = d.instruments[i];
        const std::string field = "interaction.instruments[" + std::to_string(i) + "].track";
        for (char c : in.name)
            if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_')
                f.fail("interaction.instruments[" + std::to_string(i) + "].name",
                       "'" + in.name + "' may only use letters, digits, '-' and '_' (it names the track file)");
        in.trackText = readFile(dir / in.trackPath);
        sim::InstrumentTrack::parse(in.trackText, (dir / in.trackPath).string()); // checked now, not in the player
        in.trackPath = "tools/" + in.name + ".track";
    }
    return d;
}

} // namespace

Project loadProject(const std::filesystem::path& dir) {
    const std::filesystem::path file = dir / "project.json";
    const std::string origin = file.string();
    const std::string text = readFile(file);
    json doc = json::parse(text, nullptr, false);
    if (doc.is_discarded()) throw InputError(origin + ": not valid JSON");
    Fields f(origin);
    if (!doc.is_object()) f.fail("(root)", "must be an object");
    f.only(doc, {"schemaVersion", "caseId", "caseVersion", "title", "instructions", "solver", "gravity", "bodies",
                 "surfaces", "accuracy", "render", "suture", "interaction"},
           "");
    Project p;
    p.dir = dir;
    p.schemaVersion = f.integer(f.req(doc, "schemaVersion", ""), "schemaVersion", 1, 1);
    p.caseId = f.str(f.req(doc, "caseId", ""), "caseId");
    p.caseVersion = f.str(f.req(doc, "caseVersion", ""), "caseVersion");
    if (auto* v = f.opt(doc, "title")) p.title = f.str(*v, "title");
    if (auto* v = f.opt(doc, "instructions")) p.instructions = f.str(*v, "instructions");
    if (auto* v = f.opt(doc, "render")) {
        if (!v->is_object()) f.fail("render", "must be an object");
        p.render = v->dump();
        render::RenderSettings check;
        render::applyCaseRender(check, p.render, origin); // names the field and the rule
    }
    const json& solver = f.req(doc, "solver", "");
    f.only(solver, {"type", "dt", "substeps", "iterations", "damping", "max_speed", "threads", "primal_correction"},
           "solver");
    const std::string type = f.str(f.req(solver, "type", "solver"), "solver.type");
    if (type != "xpbd" && type != "fem") f.fail("solver.type", "'" + type + "' is not supported (supported: xpbd, fem)");
    p.solverType = type;
    if (type == "fem") f.only(solver, {"type", "dt"}, "solver");
    if ((type == "fem") != (f.opt(doc, "suture") != nullptr))
        f.fail("suture", type == "fem" ? "solver 'fem' needs a 'suture' section" : "needs solver.type 'fem'");
    if (auto* su = f.opt(doc, "suture")) p.suture = parseSutureProject(f, *su, dir, origin);
    if (auto* in = f.opt(doc, "interaction")) {
        if (type != "xpbd") f.fail("interaction", "needs solver.type 'xpbd'");
        p.interaction = parseInteractionProject(f, *in, dir, origin);
    }
    if (auto* v = f.opt(solver, "dt")) p.solver.dt = f.positive(*v, "solver.dt");
    if (auto* v = f.opt(solver, "substeps")) p.solver.substeps = f.integer(*v, "solver.substeps", 1, 1000);
    if (auto* v = f.opt(solver, "iterations")) p.solver.iterations = f.integer(*v, "solver.iterations", 1, 1000);
    if (auto* v = f.opt(solver, "damping")) p.solver.damping = f.num(*v, "solver.damping");
    if (auto* v = f.opt(solver, "max_speed")) p.solver.maxSpeed = f.positive(*v, "solver.max_speed");
    if (auto* v = f.opt(solver, "threads")) p.solver.threads = f.integer(*v, "solver.threads", 1, 64);
    if (auto* v = f.opt(solver, "primal_correction")) {
        if (!v->is_boolean()) f.fail("solver.primal_correction", "must be true or false");
        p.solver.primalCorrection = v->get<bool>();
    }
    if (auto* a = f.opt(doc, "accuracy")) {
        f.only(*a, {"every_frames", "max_iterations"}, "accuracy");
        sim::AccuracySampling acc;
        if (auto* v = f.opt(*a, "every_frames")) acc.everyFrames = f.integer(*v, "accuracy.every_frames", 1, 1 << 30);
        if (auto* v = f.opt(*a, "max_iterations")) acc.maxIterations = f.integer(*v, "accuracy.max_iterations", 1, 10000);
        p.accuracy = acc;
    }
    p.solver.gravity = f.opt(doc, "gravity") ? f.vec3(doc["gravity"], "gravity") : sim::Vec3::Zero();
    if (auto why = sim::validate(p.solver); !why.empty()) f.fail("solver", why);

    const json& bodies = f.req(doc, "bodies", "");
    if (!bodies.is_array() || bodies.empty()) f.fail("bodies", "must be a non-empty array");
    std::set<std::string> names;
    for (size_t i = 0; i < bodies.size(); ++i) {
        const std::string path = "bodies[" + std::to_string(i) + "]";
        const json& b = bodies[i];
        if (!b.is_object()) f.fail(path, "must be an object");
        f.only(b, {"name", "mesh", "material", "fixed", "stiffness_regions", "stiffness_paint", "embedded_in",
                   "embedding_compliance"},
               path);
        BodyProject body;
        body.name = f.str(f.req(b, "name", path), path + ".name");
        bool okName = !body.name.empty() && body.name.size() <= 64;
        for (char c : body.name) okName &= std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_';
        if (!okName) f.fail(path + ".name", "must be 1-64 characters of [A-Za-z0-9_-]");
        if (!names.insert(body.name).second) f.fail(path + ".name", "'" + body.name + "' is used twice");
        body.mesh = parseMeshSource(f, f.req(b, "mesh", path), path + ".mesh", dir);
        body.material = sim::parseMaterial(f.req(b, "material", path), path + ".material", origin);
        if (auto* regions = f.opt(b, "stiffness_regions")) {
            if (!regions->is_array()) f.fail(path + ".stiffness_regions", "must be an array");
            for (size_t k = 0; k < regions->size(); ++k) {
                const std::string rp = path + ".stiffness_regions[" + std::to_string(k) + "]";
                const json& rj = (*regions)[k];
                f.only(rj, {"min", "max", "weight"}, rp);
                StiffnessRegion reg;
                reg.min = f.vec3(f.req(rj, "min", rp), rp + ".min");
                reg.max = f.vec3(f.req(rj, "max", rp), rp + ".max");
                reg.weight = f.positive(f.req(rj, "weight", rp), rp + ".weight");
                body.stiffnessRegions.push_back(reg);
            }
        }
        if (auto* sp = f.opt(b, "stiffness_paint")) body.paint = parsePaint(f, *sp, path + ".stiffness_paint", origin);
        if (auto* v = f.opt(b, "embedded_in")) body.embeddedIn = f.str(*v, path + ".embedded_in");
        if (auto* v = f.opt(b, "embedding_compliance")) body.embeddingCompliance = f.num(*v, path + ".embedding_compliance");
        if (auto* fx = f.opt(b, "fixed")) {
            f.only(*fx, {"min", "max"}, path + ".fixed");
            sim::Vec3 lo = f.vec3(f.req(*fx, "min", path + ".fixed"), path + ".fixed.min");
            sim::Vec3 hi = f.vec3(f.req(*fx, "max", path + ".fixed"), path + ".fixed.max");
            if (!(lo.array() <= hi.array()).all()) f.fail(path + ".fixed", "min must not exceed max");
            body.fixedBox = std::array<sim::Vec3, 2>{lo, hi};
        }
        p.bodies.push_back(std::move(body));
    }
    for (size_t i = 0; i < p.bodies.size(); ++i) {
        const std::string& cage = p.bodies[i].embeddedIn;
        if (!cage.empty() && (!names.count(cage) || cage == p.bodies[i].name))
            f.fail("bodies[" + std::to_string(i) + "].embedded_in", "'" + cage + "' is not another body of the project");
    }
    if (auto* surfaces = f.opt(doc, "surfaces")) {
        if (!surfaces->is_array()) f.fail("surfaces", "must be an array");
        for (size_t i = 0; i < surfaces->size(); ++i) {
            const std::string path = "surfaces[" + std::to_string(i) + "]";
            const json& sj = (*surfaces)[i];
            f.only(sj, {"name", "from_boundary_of", "region", "areal_density", "stretch_stiffness", "attach_distance",
                        "attach_compliance"},
                   path);
            SurfaceProject sp;
            sp.name = f.str(f.req(sj, "name", path), path + ".name");
            if (sp.name.empty() || !names.insert(sp.name).second) f.fail(path + ".name", "must be non-empty and unique");
            sp.fromBoundaryOf = f.str(f.req(sj, "from_boundary_of", path), path + ".from_boundary_of");
            if (!names.count(sp.fromBoundaryOf)) f.fail(path + ".from_boundary_of", "'" + sp.fromBoundaryOf + "' is not a body");
            if (auto* r = f.opt(sj, "region")) {
                f.only(*r, {"min", "max"}, path + ".region");
                sp.region = std::array<sim::Vec3, 2>{f.vec3(f.req(*r, "min", path + ".region"), path + ".region.min"),
                                                     f.vec3(f.req(*r, "max", path + ".region"), path + ".region.max")};
            }
            if (auto* v = f.opt(sj, "areal_density")) sp.arealDensity = f.positive(*v, path + ".areal_density");
            if (auto* v = f.opt(sj, "stretch_stiffness")) sp.stretchStiffness = f.num(*v, path + ".stretch_stiffness");
            if (auto* v = f.opt(sj, "attach_distance")) sp.attachDistance = f.positive(*v, path + ".attach_distance");
            if (auto* v = f.opt(sj, "attach_compliance")) sp.attachCompliance = f.num(*v, path + ".attach_compliance");
            p.surfaces.push_back(std::move(sp));
        }
    }
    if (p.interaction) { // names are checked now, before any meshing
        std::vector<std::string> bodies, surfaces;
        for (const BodyProject& b : p.bodies) bodies.push_back(b.name);
        for (const SurfaceProject& sp : p.surfaces) surfaces.push_back(sp.name);
        sim::checkInteractionNames(*p.interaction, bodies, surfaces, origin);
    }
    return p;
}

std::unique_ptr<sim::TetMesh> buildBodyMesh(const BodyProject& body, const std::string& origin) {
    const MeshSource& s = body.mesh;
    bake::MeshingParams params = s.meshing;
    params.label = origin + ": body '" + body.name + "'";
    switch (s.kind) {
    case MeshSource::Kind::Box: return sim::makeBoxTetMesh(s.box);
    case MeshSource::Kind::Ellipsoid:
        return bake::tetrahedralize(sim::makeEllipsoidSurface(s.center, s.radii, s.slices, s.stacks), params).mesh;
    case MeshSource::Kind::Liver:
        return bake::tetrahedralize(sim::makeLiverSurface(s.center, s.radii, s.wedge, s.slices, s.stacks), params).mesh;
    case MeshSource::Kind::Tube:
        return bake::tetrahedralize(sim::makeTubeSurface(s.center, s.end, s.radius, s.slices, s.stacks), params).mesh;
    case MeshSource::Kind::HollowTube: return sim::makeHollowTubeTetMesh(s.hollow);
    case MeshSource::Kind::File: {
        bake::ImportOptions opt;
        opt.scale = s.scale;
        params.label = s.file.filename().string();
        return bake::tetrahedralize(bake::importSurface(s.file, opt), params).mesh;
    }
    }
    throw InputError(origin + ": unknown mesh source");
}

namespace {

bool inBox(const sim::Vec3& p, const sim::Vec3& lo, const sim::Vec3& hi) {
    return (p.array() >= lo.array()).all() && (p.array() <= hi.array()).all();
}

/// The boundary triangles of `mesh` whose centroid lies in `region` (all when absent), as a
/// surface with its own compacted vertices.
sim::TriMesh cutBoundary(sim::TetMesh& mesh, const std::optional<std::array<sim::Vec3, 2>>& region) {
    mesh.requireLevel(3);
    const sim::TriMesh& b = mesh.boundary();
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

} // namespace

ExportResult exportCase(const Project& project, const std::filesystem::path& out, const ExportProgress& progress) {
    auto stage = [&](const std::string& s) {
        if (progress) progress(s);
    };
    const std::string origin = (project.dir / "project.json").string();
    sim::SceneDesc scene;
    scene.solverType = project.solverType;
    scene.suture = project.suture;
    scene.interaction = project.interaction;
    scene.xpbd = project.solver;
    scene.instructions = project.instructions;
    scene.render = project.render;
    scene.accuracy = project.accuracy;

    ExportResult result;
    std::vector<std::pair<std::string, std::string>> files;
    std::vector<std::unique_ptr<sim::TetMesh>> meshes;
    for (size_t i = 0; i < project.bodies.size(); ++i) {
        const BodyProject& b = project.bodies[i];
        const std::string field = "bodies[" + std::to_string(i) + "] ('" + b.name + "')";
        stage("meshing body '" + b.name + "'");
        std::unique_ptr<sim::TetMesh> mesh;
        try {
            mesh = buildBodyMesh(b, origin);
        } catch (const std::invalid_argument& e) {
            throw InputError(origin + ": " + field + ".mesh: " + e.what());
        }
        BodyExport be;
        be.name = b.name;
        be.nodes = mesh->vertexCount();
        be.tets = mesh->tetCount();
        be.quality = mesh->quality();
        if (!be.quality.inverted.empty())
            throw InputError(origin + ": " + field + ".mesh: tet " + std::to_string(be.quality.inverted.front()) +
                             " is inverted (" + std::to_string(be.quality.inverted.size()) + " inverted in all)");
        if (!be.quality.degenerate.empty())
            throw InputError(origin + ": " + field + ".mesh: tet " + std::to_string(be.quality.degenerate.front()) +
                             " is degenerate (" + std::to_string(be.quality.degenerate.size()) + " in all)");
        sim::BodyDesc desc;
        desc.name = b.name;
        desc.meshPath = "meshes/" + b.name + ".vtet";
        desc.material = b.material;
        desc.embeddedIn = b.embeddedIn;
        desc.embeddingCompliance = b.embeddingCompliance;
        const auto& pos = mesh->positions();
        if (b.fixedBox) {
            for (int32_t v = 0; v < static_cast<int32_t>(pos.size()); ++v)
                if (inBox(pos[v], (*b.fixedBox)[0], (*b.fixedBox)[1])) desc.fixedNodes.push_back(v);
            if (desc.fixedNodes.empty()) throw InputError(origin + ": " + field + ".fixed: the box contains no mesh node");
        }
        if (!b.stiffnessRegions.empty()) {
            desc.nodeWeights.assign(pos.size(), 1.0);
            for (size_t v = 0; v < pos.size(); ++v)
                for (const StiffnessRegion& r : b.stiffnessRegions)
                    if (inBox(pos[v], r.min, r.max)) desc.nodeWeights[v] = r.weight;
        }
        if (b.paint) {
            stage("skeleton and stiffness paint of '" + b.name + "'");
            sim::StiffnessPaintResult paint;
            try {
                bake::SkeletonParams skp = b.paint->skeleton;
                skp.label = origin + ": " + field + ".stiffness_paint.skeleton";
                const bake::SkeletonResult sk = bake::extractSkeleton(*mesh, skp);
                paint = sim::bakeStiffnessPaint(*mesh, sk.skeleton, b.paint->strokes, b.paint->params);
            } catch (const std::invalid_argument& e) {
                throw InputError(origin + ": " + field + ".stiffness_paint: " + e.what());
            }
            if (desc.nodeWeights.empty()) desc.nodeWeights = paint.weights;
            else
                for (size_t v = 0; v < pos.size(); ++v) desc.nodeWeights[v] *= paint.weights[v];
            desc.nodeWeightsPath = "meshes/" + b.name + ".vweights";
            files.emplace_back(desc.nodeWeightsPath, sim::formatNodeWeights(desc.nodeWeights));
        }
        be.fixedNodes = desc.fixedNodes.size();
        files.emplace_back(desc.meshPath, sim::formatVtet(*mesh));
        scene.bodies.push_back(std::move(desc));
        result.bodies.push_back(std::move(be));
        meshes.push_back(std::move(mesh));
    }
    std::vector<sim::TriMesh> surfaces;
    for (size_t s = 0; s < project.surfaces.size(); ++s) {
        const SurfaceProject& sp = project.surfaces[s];
        stage("cutting surface '" + sp.name + "'");
        size_t body = 0;
        while (project.bodies[body].name != sp.fromBoundaryOf) ++body;
        sim::TriMesh tri;
        try {
            tri = cutBoundary(*meshes[body], sp.region);
        } catch (const std::invalid_argument&) {
            throw InputError(origin + ": surfaces[" + std::to_string(s) + "].region: contains no boundary triangle of '" +
                             sp.fromBoundaryOf + "'");
        }
        sim::SurfaceDesc sd;
        sd.name = sp.name;
        sd.meshPath = "meshes/" + sp.name + ".vtri";
        sd.arealDensity = sp.arealDensity;
        sd.stretchStiffness = sp.stretchStiffness;
        sd.attachTo = sp.fromBoundaryOf;
        sd.attachDistance = sp.attachDistance;
        sd.attachCompliance = sp.attachCompliance;
        files.emplace_back(sd.meshPath, sim::formatVtri(tri));
        scene.surfaces.push_back(std::move(sd));
        surfaces.push_back(std::move(tri));
    }
    // Features: only what the scene needs. The player runs what it loads, so assemble the world
    // here exactly as the player will and refuse a case that cannot be simulated stably.
    const std::vector<std::string> features = sim::requiredFeatures(scene);
    stage("checking the scene");
    sim::World::assemble(scene, std::move(meshes), std::move(surfaces), features, origin);

    stage("packaging");
    vcase::Manifest header;
    header.caseId = project.caseId;
    header.caseVersion = project.caseVersion;
    header.minPlayerVersion = VISCERA_VERSION;
    if (!project.title.empty()) header.title = project.title;
    header.features = features;
    vcase::CaseWriter writer(header);
    writer.addFile("scene.json", sim::formatScene(scene));
    for (auto& [path, bytes] : files) writer.addFile(path, std::move(bytes));
    if (scene.suture) writer.addFile(scene.suture->trajectoryPath, scene.suture->trajectoryText);
    if (scene.interaction)
        for (const sim::InstrumentDesc& in : scene.interaction->instruments) writer.addFile(in.trackPath, in.trackText);
    vcase::Manifest written = writer.write(out);
    result.casePath = out;
    result.features = written.features;
    result.bytes = std::filesystem::file_size(out);
    return result;
}

} // namespace viscera::studio
