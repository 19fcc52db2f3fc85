#include "sim/scene/scene.hpp"

#include "sim/scene/scene_json.hpp"
#include "sim/util/error.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>

namespace viscera::sim {
namespace {

using nlohmann::json;

TetStrainLimits readStrainLimits(const JsonField& j) {
    j.object({"axes", "limits"});
    TetStrainLimits s;
    if (auto a = j.find("axes")) {
        if (!a->value().is_array() || a->value().size() != 3) a->fail("must be 3 axis vectors");
        const std::vector<JsonField> axes = a->items();
        for (int c = 0; c < 3; ++c)
            s.axes.col(c) = axes[c].vec3();
        if (!(s.axes.transpose() * s.axes).isIdentity(1e-9)) a->fail("must be orthonormal");
    }
    for (const JsonField& l : j["limits"].items(1)) {
        l.object({"i", "j", "lower", "upper", "compliance"});
        StrainLimit lim;
        lim.i = l["i"].integer(0, 2);
        lim.j = l["j"].integer(0, 2);
        lim.lower = l.number("lower", lim.lower);
        lim.upper = l.number("upper", lim.upper);
        if (l.has("lower") && l.has("upper") && lim.lower > lim.upper) l.fail("lower must not exceed upper");
        lim.compliance = l.number("compliance", 0.0, NumberRule::nonNegative());
        if (auto why = validate(lim, 3); !why.empty()) l.fail(why); // a limit needs a finite bound
        s.limits.push_back(lim);
    }
    return s;
}

json strainLimitsJson(const TetStrainLimits& s) {
    json lim = json::array();
    for (const StrainLimit& l : s.limits) {
        json j = {{"i", l.i}, {"j", l.j}, {"compliance", l.compliance}};
        if (std::isfinite(l.lower)) j["lower"] = l.lower; // infinite bounds are written as absent
        if (std::isfinite(l.upper)) j["upper"] = l.upper;
        lim.push_back(j);
    }
    const Mat3& a = s.axes;
    return {{"axes", {{a(0, 0), a(1, 0), a(2, 0)}, {a(0, 1), a(1, 1), a(2, 1)}, {a(0, 2), a(1, 2), a(2, 2)}}},
            {"limits", lim}};
}

} // namespace

std::vector<std::string> readSteps(const JsonField& steps) {
    std::vector<std::string> out;
    for (const JsonField& s : steps.items(0, kMaxSteps)) {
        out.push_back(s.displayText(kMaxStepBytes));
        if (out.back().empty()) s.fail("must not be empty (a step the trainee reads)");
    }
    return out;
}

void writeSteps(const std::vector<std::string>& steps, json& doc) {
    if (!steps.empty()) doc["steps"] = steps;
}

std::vector<ToolDesc> readTools(const JsonField& tools, std::set<std::string>& names) {
    std::vector<ToolDesc> out;
    const std::vector<JsonField> list = tools.items();
    if (list.size() > 2) tools.fail("at most 2 tools (one per master)");
    for (const JsonField& t : list) {
        t.object({"name", "shape", "radius", "hand", "start", "motion_scale", "force_scale", "stiffness", "max_force_n",
                  "damage_force_n", "port"});
        ToolDesc d;
        d.name = readName(t["name"], names);
        if (auto shape = t.find("shape")) shape->choice({"sphere"}, "a tool shape");
        if (auto hand = t.find("hand")) d.hand = hand->choice({"left", "right", "any"}, "a hand");
        d.start = t["start"].vec3();
        d.radius = t.number("radius", d.radius, NumberRule::aboveUpTo(0, 0.1));
        d.motionScale = t.number("motion_scale", d.motionScale, NumberRule::aboveUpTo(0, 10.0));
        d.forceScale = t.number("force_scale", d.forceScale, NumberRule::aboveUpTo(0, 10.0));
        d.maxForceN = t.number("max_force_n", d.maxForceN, NumberRule::aboveUpTo(0, 50.0));
        if (auto f = t.find("damage_force_n")) d.damageForceN = f->number(NumberRule::aboveUpTo(0, 1000.0));
        d.stiffness = t.number("stiffness", d.stiffness, NumberRule::nonNegative());
        if (auto port = t.find("port")) readPort(*port, d.port);
        out.push_back(d);
    }
    return out;
}

void readPort(const JsonField& port, PortDesc& out) {
    port.object({"position", "insertion", "max_angle_deg", "shaft_length", "mode"});
    out.declared = true;
    out.position = port["position"].vec3();
    if (auto ins = port.find("insertion")) {
        const std::vector<JsonField> range = ins->items(2, 2);
        out.insertionMin = range[0].number(NumberRule::aboveUpTo(0, 0.5));
        out.insertionMax = range[1].number(NumberRule::aboveUpTo(0, 0.5));
        if (!(out.insertionMin < out.insertionMax)) ins->fail("must be [min, max] with min < max");
    }
    out.maxAngleDeg = port.number("max_angle_deg", out.maxAngleDeg, NumberRule::aboveUpTo(0, 89));
    out.shaftLength = port.number("shaft_length", out.shaftLength, NumberRule::aboveUpTo(0, 1.0));
    if (out.shaftLength < out.insertionMax + 0.05)
        port.failAt("shaft_length", "must be at least the largest insertion + 0.05 m (" +
                                        std::to_string(out.insertionMax + 0.05) + ")");
    if (auto mode = port.find("mode"))
        out.mode = mode->choice({"laparoscopic", "robotic"}, "a port mode") == "robotic" ? PortMode::Robotic
                                                                                         : PortMode::Laparoscopic;
}

void writePort(const PortDesc& p, json& port) {
    port["position"] = {p.position.x(), p.position.y(), p.position.z()};
    port["insertion"] = {p.insertionMin, p.insertionMax};
    port["max_angle_deg"] = p.maxAngleDeg;
    port["shaft_length"] = p.shaftLength;
    port["mode"] = portModeName(p.mode);
}

std::vector<SceneryDesc> readScenery(const JsonField& scenery, std::set<std::string>& names) {
    std::vector<SceneryDesc> out;
    for (const JsonField& j : scenery.items(1, 16)) {
        j.object({"name", "mesh"});
        SceneryDesc d;
        d.name = readName(j["name"], names);
        d.meshPath = j["mesh"].entryPath();
        out.push_back(std::move(d));
    }
    return out;
}

void writeScenery(const std::vector<SceneryDesc>& scenery, json& doc) {
    for (const SceneryDesc& d : scenery)
        doc["scenery"].push_back({{"name", d.name}, {"mesh", d.meshPath}});
}

LaparoscopeDesc readLaparoscope(const JsonField& scope) {
    scope.object({"port", "tip", "optic_deg", "fov_deg", "hand", "motion_scale"});
    LaparoscopeDesc d;
    const JsonField port = scope["port"];
    readPort(port, d.port);
    d.port.mode = PortMode::Robotic; // a scope holder: the port is a remote centre of motion
    d.tip = scope["tip"].vec3();     // within the port's reach: checked by World::assemble (restTipError)
    if (auto optic = scope.find("optic_deg")) {
        d.opticDeg = optic->number(NumberRule::closed(0, 30));
        if (d.opticDeg != 0 && d.opticDeg != 30) optic->fail("must be 0 or 30 (the optics made)");
    }
    d.fovDeg = scope.number("fov_deg", d.fovDeg, NumberRule::closed(20, 120));
    if (auto hand = scope.find("hand")) d.hand = hand->choice({"left", "right", "any"}, "a hand");
    d.motionScale = scope.number("motion_scale", d.motionScale, NumberRule::aboveUpTo(0, 10.0));
    return d;
}

void writeLaparoscope(const LaparoscopeDesc& d, json& doc) {
    json& j = doc["laparoscope"];
    writePort(d.port, j["port"]);
    j["tip"] = {d.tip.x(), d.tip.y(), d.tip.z()};
    j["optic_deg"] = d.opticDeg;
    j["fov_deg"] = d.fovDeg;
    j["hand"] = d.hand;
    j["motion_scale"] = d.motionScale;
}

void readDeviceMapping(const JsonField& dev, DeviceMapping& out) {
    out.declared = true;
    if (auto hand = dev.find("hand")) out.hand = hand->choice({"left", "right", "any"}, "a hand");
    out.motionScale = dev.number("motion_scale", out.motionScale, NumberRule::aboveUpTo(0, 10.0));
    out.forceScale = dev.number("force_scale", out.forceScale, NumberRule::aboveUpTo(0, 100.0));
    out.maxForceN = dev.number("max_force_n", out.maxForceN, NumberRule::aboveUpTo(0, 50.0));
}

void writeDeviceMapping(const DeviceMapping& m, json& device) {
    device["hand"] = m.hand;
    device["motion_scale"] = m.motionScale;
    device["force_scale"] = m.forceScale;
    device["max_force_n"] = m.maxForceN;
}

void writeTools(const std::vector<ToolDesc>& tools, json& doc) {
    for (const ToolDesc& t : tools) {
        doc["tools"].push_back({{"name", t.name},
                                {"shape", "sphere"},
                                {"radius", t.radius},
                                {"hand", t.hand},
                                {"start", {t.start.x(), t.start.y(), t.start.z()}},
                                {"motion_scale", t.motionScale},
                                {"force_scale", t.forceScale},
                                {"stiffness", t.stiffness},
                                {"max_force_n", t.maxForceN}});
        if (t.damageForceN) doc["tools"].back()["damage_force_n"] = *t.damageForceN;
        if (t.port.declared) writePort(t.port, doc["tools"].back()["port"]);
    }
}

void readSolver(const JsonField& doc, SceneDesc& scene) {
    using L = XpbdLimits;
    const JsonField solver = doc["solver"];
    solver.object({"type", "dt", "substeps", "iterations", "damping", "max_speed", "threads", "primal_correction",
                   "inertia_scaling"});
    scene.solverType = solver["type"].choice({"xpbd", "fem"}, "a supported solver");
    XpbdSettings& s = scene.xpbd;
    if (scene.solverType == "fem") solver.object({"type", "dt"}); // quasi-static suturing FEM [B §2.2]
    if (scene.solverType == "fem" && !doc.has("suture")) doc.failAt("suture", "solver 'fem' needs a 'suture' section");
    if (scene.solverType != "fem" && doc.has("suture")) doc.failAt("suture", "needs solver.type 'fem'");
    if (scene.solverType != "xpbd" && doc.has("interaction")) doc.failAt("interaction", "needs solver.type 'xpbd'");
    s.dt = solver.number("dt", s.dt, NumberRule::aboveUpTo(0, L::maxDt));
    s.substeps = solver.integer("substeps", s.substeps, 1, L::maxSubsteps);
    s.iterations = solver.integer("iterations", s.iterations, 1, L::maxIterations);
    s.threads = solver.integer("threads", s.threads, 1, L::maxThreads);
    s.damping = solver.number("damping", s.damping, NumberRule::closed(0, L::maxDamping));
    s.maxSpeed = solver.number("max_speed", s.maxSpeed, NumberRule::positive());
    s.primalCorrection = solver.boolean("primal_correction", s.primalCorrection);
    s.inertiaScaling = solver.number("inertia_scaling", s.inertiaScaling, NumberRule::closed(1, L::maxInertiaScaling));
    s.gravity = Vec3::Zero();
    if (auto g = doc.find("gravity")) {
        s.gravity = g->vec3();
        if (s.gravity.norm() > L::maxGravity) g->fail("must be at most 1000 m/s^2 in magnitude");
    }
}

void writeSolver(const SceneDesc& scene, json& doc) {
    const XpbdSettings& s = scene.xpbd;
    doc["solver"] = {{"type", scene.solverType},   {"dt", s.dt},           {"substeps", s.substeps},
                     {"iterations", s.iterations}, {"damping", s.damping}, {"max_speed", s.maxSpeed},
                     {"threads", s.threads}};
    if (s.primalCorrection) doc["solver"]["primal_correction"] = true;
    if (s.inertiaScaling > 1) doc["solver"]["inertia_scaling"] = s.inertiaScaling;
    if (scene.solverType == "fem") doc["solver"] = {{"type", "fem"}, {"dt", s.dt}};
    doc["gravity"] = {s.gravity.x(), s.gravity.y(), s.gravity.z()};
}

std::optional<AccuracySampling> readAccuracy(const JsonField& doc) {
    auto a = doc.find("accuracy");
    if (!a) return std::nullopt;
    a->object({"every_frames", "max_iterations"});
    AccuracySampling acc;
    acc.everyFrames = a->integer("every_frames", acc.everyFrames, 1, INT32_MAX);
    acc.maxIterations = a->integer("max_iterations", acc.maxIterations, 1, 10000);
    return acc;
}

void writeAccuracy(const std::optional<AccuracySampling>& accuracy, json& doc) {
    if (accuracy)
        doc["accuracy"] = {{"every_frames", accuracy->everyFrames}, {"max_iterations", accuracy->maxIterations}};
}

std::string readName(const JsonField& field, std::set<std::string>& names) {
    const std::string name = field.string();
    bool ok = !name.empty() && name.size() <= 64;
    for (char c : name)
        ok = ok && (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_');
    if (!ok) field.fail("must be 1-64 characters of [A-Za-z0-9_-]");
    if (!names.insert(name).second) field.fail("'" + name + "' is used twice");
    return name;
}

void readBodyCommon(const JsonField& b, BodyDesc& body, std::set<std::string>& names) {
    body.name = readName(b["name"], names);
    body.material = readMaterial(b["material"]);
    if (auto sl = b.find("strain_limits")) body.strainLimits = readStrainLimits(*sl);
    if (auto e = b.find("embedded_in")) body.embeddedIn = e->nonEmptyString();
    body.embeddingCompliance = b.number("embedding_compliance", body.embeddingCompliance, NumberRule::nonNegative());
}

void writeBodyCommon(const BodyDesc& desc, json& body) {
    body["name"] = desc.name;
    body["material"] = materialJson(desc.material);
    if (desc.strainLimits) body["strain_limits"] = strainLimitsJson(*desc.strainLimits);
    if (!desc.embeddedIn.empty()) body["embedded_in"] = desc.embeddedIn;
    if (!desc.embeddedIn.empty() || desc.embeddingCompliance != 0)
        body["embedding_compliance"] = desc.embeddingCompliance;
}

void readSurfaceCommon(const JsonField& sj, SurfaceDesc& sd, std::set<std::string>& names) {
    sd.name = readName(sj["name"], names);
    sd.arealDensity = sj.number("areal_density", sd.arealDensity, NumberRule::positive());
    sd.stretchStiffness = sj.number("stretch_stiffness", sd.stretchStiffness, NumberRule::nonNegative());
    sd.attachDistance = sj.number("attach_distance", sd.attachDistance, NumberRule::positive());
    sd.attachCompliance = sj.number("attach_compliance", sd.attachCompliance, NumberRule::nonNegative());
}

void writeSurfaceCommon(const SurfaceDesc& desc, json& surface) {
    surface["name"] = desc.name;
    surface["areal_density"] = desc.arealDensity;
    surface["stretch_stiffness"] = desc.stretchStiffness;
    surface["attach_distance"] = desc.attachDistance;
    surface["attach_compliance"] = desc.attachCompliance;
}

void checkSceneReferences(const std::vector<const BodyDesc*>& bodies, const std::vector<const SurfaceDesc*>& surfaces,
                          const InteractionDesc* interaction, const std::string& origin) {
    std::vector<std::string> bodyNames, surfaceNames;
    for (const BodyDesc* b : bodies)
        bodyNames.push_back(b->name);
    for (const SurfaceDesc* s : surfaces)
        surfaceNames.push_back(s->name);
    for (size_t i = 0; i < bodies.size(); ++i) {
        const std::string& cage = bodies[i]->embeddedIn;
        if (!cage.empty() &&
            (cage == bodies[i]->name || std::find(bodyNames.begin(), bodyNames.end(), cage) == bodyNames.end()))
            throw InputError(origin + ": bodies[" + std::to_string(i) + "].embedded_in: '" + cage +
                             "' is not another body of the scene");
    }
    if (interaction) checkInteractionNames(*interaction, bodyNames, surfaceNames, origin);
}

namespace {

/// "node_weights" (inline, one positive number per node) or "node_weights_file" (a .vweights
/// entry of the case), for bodies and surfaces alike.
void readNodeWeightFields(const JsonField& j, std::vector<double>& weights, std::string& path) {
    if (auto w = j.find("node_weights"))
        for (const JsonField& x : w->items())
            weights.push_back(x.number(NumberRule::positive()));
    if (auto f = j.find("node_weights_file")) {
        if (j.has("node_weights")) f->fail("give node_weights or node_weights_file, not both");
        path = f->entryPath();
    }
}

void writeNodeWeightFields(const std::vector<double>& weights, const std::string& path, json& j) {
    if (!path.empty())
        j["node_weights_file"] = path;
    else if (!weights.empty())
        j["node_weights"] = weights;
}

} // namespace

void checkAssessmentMeasurable(const SceneDesc& scene, const std::vector<std::string>& bodies,
                               const std::string& origin) {
    if (!scene.assessment) return;
    std::string all; // every problem, not the first only
    for (const std::string& p : unmeasurableMetrics(*scene.assessment, scene, bodies))
        all += (all.empty() ? "" : "; ") + p;
    if (!all.empty()) throw InputError(origin + ": " + all);
}

SceneDesc parseScene(std::string_view text, const std::string& origin) {
    const json doc = parseJsonText(text, origin);
    const JsonField root(doc, "", origin);
    root.object({"solver", "gravity", "instructions", "steps", "accuracy", "bodies", "surfaces", "tools", "render",
                 "suture", "interaction", "laparoscope", "scenery", "assessment"});
    SceneDesc scene;
    readSolver(root, scene);
    if (auto su = root.find("suture")) scene.suture = readSutureSection(*su);
    if (auto v = root.find("instructions")) scene.instructions = v->displayText(kMaxInstructionsBytes);
    if (auto v = root.find("steps")) scene.steps = readSteps(*v);
    if (auto v = root.find("render")) scene.render = v->anyObject().value().dump();
    scene.accuracy = readAccuracy(root);

    std::set<std::string> names;
    for (const JsonField& b : root["bodies"].items(1)) {
        b.object({"name", "mesh", "material", "fixed_nodes", "node_weights", "node_weights_file", "sample_map_file",
                  "strain_limits", "embedded_in", "embedding_compliance"});
        BodyDesc body;
        readBodyCommon(b, body, names);
        body.meshPath = b["mesh"].entryPath();
        if (auto f = b.find("fixed_nodes")) body.fixedNodes = f->indices();
        readNodeWeightFields(b, body.nodeWeights, body.nodeWeightsPath);
        if (auto f = b.find("sample_map_file")) body.sampleMapPath = f->entryPath();
        scene.bodies.push_back(std::move(body));
    }
    if (auto surfaces = root.find("surfaces"))
        for (const JsonField& sj : surfaces->items()) {
            sj.object({"name", "mesh", "areal_density", "stretch_stiffness", "attach_to", "attach_distance",
                       "attach_compliance", "fixed_nodes", "node_weights", "node_weights_file"});
            SurfaceDesc sd;
            readSurfaceCommon(sj, sd, names);
            sd.meshPath = sj["mesh"].entryPath();
            if (auto a = sj.find("attach_to")) {
                sd.attachTo = a->string();
                bool found = false;
                for (const auto& b : scene.bodies)
                    found |= b.name == sd.attachTo;
                if (!found) a->fail("'" + sd.attachTo + "' is not a body of the scene");
            }
            if (auto f = sj.find("fixed_nodes")) sd.fixedNodes = f->indices();
            readNodeWeightFields(sj, sd.nodeWeights, sd.nodeWeightsPath);
            scene.surfaces.push_back(std::move(sd));
        }
    if (auto t = root.find("tools")) scene.tools = readTools(*t, names);
    if (auto l = root.find("laparoscope")) scene.laparoscope = readLaparoscope(*l);
    if (auto a = root.find("assessment")) scene.assessment = readAssessment(*a);
    if (auto sc = root.find("scenery")) scene.scenery = readScenery(*sc, names);
    if (auto in = root.find("interaction")) scene.interaction = readInteractionSection(*in);
    std::vector<const BodyDesc*> bodies;
    for (const BodyDesc& b : scene.bodies)
        bodies.push_back(&b);
    std::vector<const SurfaceDesc*> surfaces;
    for (const SurfaceDesc& s : scene.surfaces)
        surfaces.push_back(&s);
    checkSceneReferences(bodies, surfaces, scene.interaction ? &*scene.interaction : nullptr, origin);
    std::vector<std::string> bodyNames;
    for (const BodyDesc& b : scene.bodies)
        bodyNames.push_back(b.name);
    checkAssessmentMeasurable(scene, bodyNames, origin);
    return scene;
}

json sceneJson(const SceneDesc& scene) {
    json doc;
    writeSolver(scene, doc);
    if (scene.suture) doc["suture"] = sutureJson(*scene.suture);
    if (scene.interaction) doc["interaction"] = interactionJson(*scene.interaction);
    if (!scene.instructions.empty()) doc["instructions"] = scene.instructions;
    writeSteps(scene.steps, doc);
    if (!scene.render.empty()) doc["render"] = json::parse(scene.render);
    writeAccuracy(scene.accuracy, doc);
    doc["bodies"] = json::array();
    for (const BodyDesc& b : scene.bodies) {
        json j = {{"mesh", b.meshPath}, {"fixed_nodes", b.fixedNodes}};
        writeBodyCommon(b, j);
        writeNodeWeightFields(b.nodeWeights, b.nodeWeightsPath, j);
        if (!b.sampleMapPath.empty()) j["sample_map_file"] = b.sampleMapPath;
        doc["bodies"].push_back(j);
    }
    if (!scene.surfaces.empty()) {
        doc["surfaces"] = json::array();
        for (const SurfaceDesc& sd : scene.surfaces) {
            json j = {{"mesh", sd.meshPath}, {"fixed_nodes", sd.fixedNodes}};
            writeSurfaceCommon(sd, j);
            if (!sd.attachTo.empty()) j["attach_to"] = sd.attachTo;
            writeNodeWeightFields(sd.nodeWeights, sd.nodeWeightsPath, j);
            doc["surfaces"].push_back(j);
        }
    }
    writeTools(scene.tools, doc);
    if (scene.laparoscope) writeLaparoscope(*scene.laparoscope, doc);
    if (scene.assessment) writeAssessment(*scene.assessment, doc);
    writeScenery(scene.scenery, doc);
    return doc;
}

std::string formatScene(const SceneDesc& scene) {
    return sceneJson(scene).dump(2) + "\n";
}

} // namespace viscera::sim
