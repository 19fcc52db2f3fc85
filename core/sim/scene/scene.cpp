#include "sim/scene/scene.hpp"

#include "sim/scene/material_json.hpp"
#include "sim/util/error.hpp"

#include <nlohmann/json.hpp>

#include <climits>
#include <cmath>
#include <set>

namespace viscera::sim {
namespace {

using nlohmann::json;

class Reader {
public:
    explicit Reader(const std::string& origin) : m_origin(origin) {}
    const std::string& origin() const { return m_origin; }
    [[noreturn]] void fail(const std::string& field, const std::string& rule) const {
        throw InputError(m_origin + ": " + field + ": " + rule);
    }
    const json& require(const json& obj, const std::string& key, const std::string& path) const {
        if (!obj.is_object()) fail(path.empty() ? "(root)" : path, "must be an object");
        auto it = obj.find(key);
        if (it == obj.end()) fail(path.empty() ? key : path + "." + key, "required field is missing");
        return *it;
    }
    void only(const json& obj, std::initializer_list<const char*> keys, const std::string& path) const {
        if (!obj.is_object()) fail(path.empty() ? "(root)" : path, "must be an object");
        for (auto it = obj.begin(); it != obj.end(); ++it) {
            bool known = false;
            for (const char* k : keys) known |= it.key() == k;
            if (!known) fail(path.empty() ? it.key() : path + "." + it.key(), "unknown field");
        }
    }
    double number(const json& v, const std::string& field) const {
        if (!v.is_number()) fail(field, "must be a number");
        double d = v.get<double>();
        if (!std::isfinite(d)) fail(field, "must be finite");
        return d;
    }
    double nonNegative(const json& v, const std::string& field) const {
        double d = number(v, field);
        if (d < 0) fail(field, "must not be negative");
        return d;
    }
    int integer(const json& v, const std::string& field) const {
        if (!v.is_number_integer()) fail(field, "must be an integer");
        auto i = v.get<int64_t>();
        if (i < INT32_MIN || i > INT32_MAX) fail(field, "is out of range");
        return static_cast<int>(i);
    }
    std::string string(const json& v, const std::string& field) const {
        if (!v.is_string()) fail(field, "must be a string");
        return v.get<std::string>();
    }
    Vec3 vec3(const json& v, const std::string& field) const {
        if (!v.is_array() || v.size() != 3) fail(field, "must be an array of 3 numbers");
        return {number(v[0], field + "[0]"), number(v[1], field + "[1]"), number(v[2], field + "[2]")};
    }
    double optNumber(const json& obj, const char* key, const std::string& path, double def) const {
        auto it = obj.find(key);
        return it == obj.end() ? def : number(*it, path + "." + key);
    }
    std::vector<int32_t> indices(const json& obj, const char* key, const std::string& path) const {
        std::vector<int32_t> out;
        auto it = obj.find(key);
        if (it == obj.end()) return out;
        const std::string f = path + "." + key;
        if (!it->is_array()) fail(f, "must be an array of vertex indices");
        for (size_t k = 0; k < it->size(); ++k) {
            int v = integer((*it)[k], f + "[" + std::to_string(k) + "]");
            if (v < 0) fail(f + "[" + std::to_string(k) + "]", "must be non-negative");
            out.push_back(v);
        }
        return out;
    }

private:
    const std::string& m_origin;
};

TetStrainLimits parseStrainLimits(const Reader& r, const json& j, const std::string& path) {
    r.only(j, {"axes", "limits"}, path);
    TetStrainLimits s;
    if (j.contains("axes")) {
        const json& a = j["axes"];
        if (!a.is_array() || a.size() != 3) r.fail(path + ".axes", "must be 3 axis vectors");
        for (int c = 0; c < 3; ++c) s.axes.col(c) = r.vec3(a[c], path + ".axes[" + std::to_string(c) + "]");
        if (!(s.axes.transpose() * s.axes).isIdentity(1e-9)) r.fail(path + ".axes", "must be orthonormal");
    }
    const json& lim = r.require(j, "limits", path);
    if (!lim.is_array() || lim.empty()) r.fail(path + ".limits", "must be a non-empty array");
    for (size_t k = 0; k < lim.size(); ++k) {
        const std::string lp = path + ".limits[" + std::to_string(k) + "]";
        r.only(lim[k], {"i", "j", "lower", "upper", "compliance"}, lp);
        StrainLimit l;
        l.i = r.integer(r.require(lim[k], "i", lp), lp + ".i");
        l.j = r.integer(r.require(lim[k], "j", lp), lp + ".j");
        l.lower = r.optNumber(lim[k], "lower", lp, l.lower);
        l.upper = r.optNumber(lim[k], "upper", lp, l.upper);
        l.compliance = r.optNumber(lim[k], "compliance", lp, 0.0);
        if (auto why = validate(l, 3); !why.empty()) r.fail(lp, why);
        s.limits.push_back(l);
    }
    return s;
}

std::vector<ToolDesc> parseTools(const Reader& r, const json& tools, std::set<std::string>& names) {
    if (!tools.is_array()) r.fail("tools", "must be an array");
    if (tools.size() > 2) r.fail("tools", "at most 2 tools (one per master)");
    std::vector<ToolDesc> out;
    for (size_t i = 0; i < tools.size(); ++i) {
        const std::string p = "tools[" + std::to_string(i) + "]";
        const json& t = tools[i];
        r.only(t, {"name", "shape", "radius", "hand", "start", "motion_scale", "force_scale", "stiffness", "max_force_n",
                   "damage_force_n"},
               p);
        ToolDesc d;
        d.name = r.string(r.require(t, "name", p), p + ".name");
        if (d.name.empty() || !names.insert(d.name).second) r.fail(p + ".name", "must be non-empty and unique");
        if (t.contains("shape") && r.string(t["shape"], p + ".shape") != "sphere") r.fail(p + ".shape", "must be 'sphere'");
        if (t.contains("hand")) d.hand = r.string(t["hand"], p + ".hand");
        if (d.hand != "left" && d.hand != "right" && d.hand != "any") r.fail(p + ".hand", "must be 'left', 'right' or 'any'");
        d.start = r.vec3(r.require(t, "start", p), p + ".start");
        auto positive = [&](const char* key, double& v, double max) {
            if (!t.contains(key)) return;
            v = r.number(t[key], p + "." + key);
            if (!(v > 0 && v <= max)) r.fail(p + "." + key, "must be in (0, " + json(max).dump() + "]");
        };
        positive("radius", d.radius, 0.1);
        positive("motion_scale", d.motionScale, 10.0);
        positive("force_scale", d.forceScale, 10.0);
        positive("max_force_n", d.maxForceN, 50.0);
        positive("damage_force_n", d.damageForceN, 1000.0);
        if (t.contains("stiffness")) d.stiffness = r.nonNegative(t["stiffness"], p + ".stiffness");
        out.push_back(d);
    }
    return out;
}

json limitNumber(double v) { return std::isfinite(v) ? json(v) : json(); }

} // namespace

SceneDesc parseScene(std::string_view text, const std::string& origin) {
    Reader r(origin);
    json doc = json::parse(text, nullptr, false);
    if (doc.is_discarded()) throw InputError(origin + ": not valid JSON");
    r.only(doc, {"solver", "gravity", "instructions", "accuracy", "bodies", "surfaces", "tools", "render", "suture",
                 "interaction"}, "");
    SceneDesc scene;
    const json& solver = r.require(doc, "solver", "");
    r.only(solver, {"type", "dt", "substeps", "iterations", "damping", "max_speed", "threads", "primal_correction"},
           "solver");
    scene.solverType = r.string(r.require(solver, "type", "solver"), "solver.type");
    if (scene.solverType != "xpbd" && scene.solverType != "fem")
        r.fail("solver.type", "'" + scene.solverType + "' is not supported (supported: xpbd, fem)");
    if (scene.solverType == "fem") { // quasi-static suturing FEM [B §2.2]: needs the suture section
        r.only(solver, {"type", "dt"}, "solver");
        if (!doc.contains("suture")) r.fail("suture", "solver 'fem' needs a 'suture' section");
    } else if (doc.contains("suture")) {
        r.fail("suture", "needs solver.type 'fem'");
    }
    if (doc.contains("suture")) scene.suture = suture::parseSutureSection(doc["suture"].dump(), origin);
    XpbdSettings& s = scene.xpbd;
    s.dt = r.optNumber(solver, "dt", "solver", s.dt);
    if (solver.contains("substeps")) s.substeps = r.integer(solver["substeps"], "solver.substeps");
    if (solver.contains("iterations")) s.iterations = r.integer(solver["iterations"], "solver.iterations");
    if (solver.contains("threads")) s.threads = r.integer(solver["threads"], "solver.threads");
    s.damping = r.optNumber(solver, "damping", "solver", s.damping);
    s.maxSpeed = r.optNumber(solver, "max_speed", "solver", s.maxSpeed);
    if (solver.contains("primal_correction")) {
        if (!solver["primal_correction"].is_boolean()) r.fail("solver.primal_correction", "must be true or false");
        s.primalCorrection = solver["primal_correction"].get<bool>();
    }
    s.gravity = doc.contains("gravity") ? r.vec3(doc["gravity"], "gravity") : Vec3::Zero();
    if (auto why = validate(s); !why.empty()) r.fail("solver", why);
    if (doc.contains("instructions")) scene.instructions = r.string(doc["instructions"], "instructions");
    if (doc.contains("render")) {
        if (!doc["render"].is_object()) r.fail("render", "must be an object");
        scene.render = doc["render"].dump();
    }
    if (doc.contains("accuracy")) {
        const json& a = doc["accuracy"];
        r.only(a, {"every_frames", "max_iterations"}, "accuracy");
        AccuracySampling acc;
        if (a.contains("every_frames")) acc.everyFrames = r.integer(a["every_frames"], "accuracy.every_frames");
        if (a.contains("max_iterations")) acc.maxIterations = r.integer(a["max_iterations"], "accuracy.max_iterations");
        if (acc.everyFrames < 1) r.fail("accuracy.every_frames", "must be at least 1");
        if (acc.maxIterations < 1 || acc.maxIterations > 10000) r.fail("accuracy.max_iterations", "must be in [1, 10000]");
        scene.accuracy = acc;
    }

    const json& bodies = r.require(doc, "bodies", "");
    if (!bodies.is_array() || bodies.empty()) r.fail("bodies", "must be a non-empty array");
    std::set<std::string> names;
    for (size_t i = 0; i < bodies.size(); ++i) {
        const std::string p = "bodies[" + std::to_string(i) + "]";
        const json& b = bodies[i];
        r.only(b, {"name", "mesh", "material", "fixed_nodes", "node_weights", "node_weights_file", "strain_limits",
                   "embedded_in", "embedding_compliance"},
               p);
        BodyDesc body;
        body.name = r.string(r.require(b, "name", p), p + ".name");
        if (body.name.empty() || !names.insert(body.name).second) r.fail(p + ".name", "must be non-empty and unique");
        body.meshPath = r.string(r.require(b, "mesh", p), p + ".mesh");
        body.material = parseMaterial(r.require(b, "material", p), p + ".material", origin);
        body.fixedNodes = r.indices(b, "fixed_nodes", p);
        if (b.contains("node_weights")) {
            const json& w = b["node_weights"];
            if (!w.is_array()) r.fail(p + ".node_weights", "must be an array of positive numbers");
            for (size_t k = 0; k < w.size(); ++k) {
                double x = r.number(w[k], p + ".node_weights[" + std::to_string(k) + "]");
                if (!(x > 0)) r.fail(p + ".node_weights[" + std::to_string(k) + "]", "must be positive");
                body.nodeWeights.push_back(x);
            }
        }
        if (b.contains("node_weights_file")) {
            if (b.contains("node_weights")) r.fail(p + ".node_weights_file", "give node_weights or node_weights_file, not both");
            body.nodeWeightsPath = r.string(b["node_weights_file"], p + ".node_weights_file");
            if (body.nodeWeightsPath.empty() || body.nodeWeightsPath.front() == '/' ||
                body.nodeWeightsPath.find("..") != std::string::npos)
                r.fail(p + ".node_weights_file", "must be a relative path inside the case");
        }
        if (b.contains("strain_limits")) body.strainLimits = parseStrainLimits(r, b["strain_limits"], p + ".strain_limits");
        if (b.contains("embedded_in")) body.embeddedIn = r.string(b["embedded_in"], p + ".embedded_in");
        if (b.contains("embedding_compliance"))
            body.embeddingCompliance = r.nonNegative(b["embedding_compliance"], p + ".embedding_compliance");
        scene.bodies.push_back(std::move(body));
    }
    for (size_t i = 0; i < scene.bodies.size(); ++i) {
        const auto& b = scene.bodies[i];
        if (!b.embeddedIn.empty() && (!names.count(b.embeddedIn) || b.embeddedIn == b.name))
            r.fail("bodies[" + std::to_string(i) + "].embedded_in", "'" + b.embeddedIn + "' is not another body of the scene");
    }
    if (doc.contains("surfaces")) {
        const json& surfaces = doc["surfaces"];
        if (!surfaces.is_array()) r.fail("surfaces", "must be an array");
        for (size_t i = 0; i < surfaces.size(); ++i) {
            const std::string p = "surfaces[" + std::to_string(i) + "]";
            const json& sj = surfaces[i];
            r.only(sj, {"name", "mesh", "areal_density", "stretch_stiffness", "attach_to", "attach_distance",
                        "attach_compliance", "fixed_nodes"},
                   p);
            SurfaceDesc sd;
            sd.name = r.string(r.require(sj, "name", p), p + ".name");
            if (sd.name.empty() || !names.insert(sd.name).second) r.fail(p + ".name", "must be non-empty and unique");
            sd.meshPath = r.string(r.require(sj, "mesh", p), p + ".mesh");
            sd.arealDensity = r.optNumber(sj, "areal_density", p, sd.arealDensity);
            if (!(sd.arealDensity > 0)) r.fail(p + ".areal_density", "must be positive");
            if (sj.contains("stretch_stiffness")) sd.stretchStiffness = r.nonNegative(sj["stretch_stiffness"], p + ".stretch_stiffness");
            if (sj.contains("attach_to")) sd.attachTo = r.string(sj["attach_to"], p + ".attach_to");
            if (sj.contains("attach_distance")) sd.attachDistance = r.nonNegative(sj["attach_distance"], p + ".attach_distance");
            if (sj.contains("attach_compliance")) sd.attachCompliance = r.nonNegative(sj["attach_compliance"], p + ".attach_compliance");
            sd.fixedNodes = r.indices(sj, "fixed_nodes", p);
            bool found = sd.attachTo.empty();
            for (const auto& b : scene.bodies) found |= b.name == sd.attachTo;
            if (!found) r.fail(p + ".attach_to", "'" + sd.attachTo + "' is not a body of the scene");
            scene.surfaces.push_back(std::move(sd));
        }
    }
    if (doc.contains("tools")) scene.tools = parseTools(r, doc["tools"], names);
    if (doc.contains("interaction")) {
        if (scene.solverType != "xpbd") r.fail("interaction", "needs solver.type 'xpbd'");
        InteractionDesc in = parseInteractionSection(doc["interaction"].dump(), origin);
        std::vector<std::string> bodies, surfaces;
        for (const auto& bd : scene.bodies) bodies.push_back(bd.name);
        for (const auto& sd : scene.surfaces) surfaces.push_back(sd.name);
        checkInteractionNames(in, bodies, surfaces, origin);
        scene.interaction = std::move(in);
    }
    return scene;
}

std::string formatScene(const SceneDesc& scene) {
    json doc;
    const XpbdSettings& s = scene.xpbd;
    doc["solver"] = {{"type", scene.solverType}, {"dt", s.dt},           {"substeps", s.substeps},
                     {"iterations", s.iterations}, {"damping", s.damping}, {"max_speed", s.maxSpeed},
                     {"threads", s.threads}};
    if (s.primalCorrection) doc["solver"]["primal_correction"] = true;
    if (scene.solverType == "fem") doc["solver"] = {{"type", "fem"}, {"dt", s.dt}};
    if (scene.suture) doc["suture"] = json::parse(suture::formatSutureSection(*scene.suture));
    if (scene.interaction) doc["interaction"] = json::parse(formatInteractionSection(*scene.interaction));
    doc["gravity"] = {s.gravity.x(), s.gravity.y(), s.gravity.z()};
    if (!scene.instructions.empty()) doc["instructions"] = scene.instructions;
    if (!scene.render.empty()) doc["render"] = json::parse(scene.render);
    if (scene.accuracy)
        doc["accuracy"] = {{"every_frames", scene.accuracy->everyFrames}, {"max_iterations", scene.accuracy->maxIterations}};
    doc["bodies"] = json::array();
    for (const BodyDesc& b : scene.bodies) {
        json j = {{"name", b.name}, {"mesh", b.meshPath}, {"material", materialToJson(b.material)}, {"fixed_nodes", b.fixedNodes}};
        if (!b.nodeWeightsPath.empty()) j["node_weights_file"] = b.nodeWeightsPath;
        else if (!b.nodeWeights.empty()) j["node_weights"] = b.nodeWeights;
        if (b.strainLimits) {
            json lim = json::array();
            for (const StrainLimit& l : b.strainLimits->limits)
                lim.push_back({{"i", l.i}, {"j", l.j}, {"lower", limitNumber(l.lower)}, {"upper", limitNumber(l.upper)},
                               {"compliance", l.compliance}});
            // Infinite bounds are written as absent.
            for (auto& l : lim)
                for (const char* k : {"lower", "upper"})
                    if (l[k].is_null()) l.erase(k);
            const Mat3& a = b.strainLimits->axes;
            j["strain_limits"] = {{"axes", {{a(0, 0), a(1, 0), a(2, 0)}, {a(0, 1), a(1, 1), a(2, 1)}, {a(0, 2), a(1, 2), a(2, 2)}}},
                                  {"limits", lim}};
        }
        if (!b.embeddedIn.empty()) {
            j["embedded_in"] = b.embeddedIn;
            j["embedding_compliance"] = b.embeddingCompliance;
        }
        doc["bodies"].push_back(j);
    }
    if (!scene.surfaces.empty()) {
        doc["surfaces"] = json::array();
        for (const SurfaceDesc& sd : scene.surfaces) {
            json j = {{"name", sd.name},
                      {"mesh", sd.meshPath},
                      {"areal_density", sd.arealDensity},
                      {"stretch_stiffness", sd.stretchStiffness},
                      {"attach_distance", sd.attachDistance},
                      {"attach_compliance", sd.attachCompliance},
                      {"fixed_nodes", sd.fixedNodes}};
            if (!sd.attachTo.empty()) j["attach_to"] = sd.attachTo;
            doc["surfaces"].push_back(j);
        }
    }
    for (const ToolDesc& t : scene.tools)
        doc["tools"].push_back({{"name", t.name}, {"shape", "sphere"}, {"radius", t.radius}, {"hand", t.hand},
                                {"start", {t.start.x(), t.start.y(), t.start.z()}}, {"motion_scale", t.motionScale},
                                {"force_scale", t.forceScale}, {"stiffness", t.stiffness}, {"max_force_n", t.maxForceN},
                                {"damage_force_n", t.damageForceN}});
    return doc.dump(2) + "\n";
}

} // namespace viscera::sim
