#include "sim/scene/scene.hpp"

#include "sim/util/error.hpp"

#include <nlohmann/json.hpp>

#include <set>

namespace viscera::sim {
namespace {

using nlohmann::json;

class Reader {
public:
    explicit Reader(const std::string& origin) : m_origin(origin) {}
    [[noreturn]] void fail(const std::string& field, const std::string& rule) const {
        throw InputError(m_origin + ": " + field + ": " + rule);
    }
    const json& require(const json& obj, const std::string& key, const std::string& path) const {
        if (!obj.is_object()) fail(path, "must be an object");
        auto it = obj.find(key);
        if (it == obj.end()) fail(path.empty() ? key : path + "." + key, "required field is missing");
        return *it;
    }
    double number(const json& v, const std::string& field) const {
        if (!v.is_number()) fail(field, "must be a number");
        double d = v.get<double>();
        if (!std::isfinite(d)) fail(field, "must be finite");
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

private:
    const std::string& m_origin;
};

} // namespace

SceneDesc parseScene(std::string_view text, const std::string& origin) {
    Reader r(origin);
    json doc = json::parse(text, nullptr, false);
    if (doc.is_discarded()) throw InputError(origin + ": not valid JSON");
    if (!doc.is_object()) r.fail("(root)", "must be an object");
    SceneDesc scene;
    const json& solver = r.require(doc, "solver", "");
    scene.solverType = r.string(r.require(solver, "type", "solver"), "solver.type");
    if (scene.solverType != "xpbd")
        r.fail("solver.type", "'" + scene.solverType + "' is not supported (supported: xpbd)");
    XpbdSettings& s = scene.xpbd;
    s.dt = r.optNumber(solver, "dt", "solver", s.dt);
    if (solver.contains("substeps")) s.substeps = r.integer(solver["substeps"], "solver.substeps");
    if (solver.contains("iterations")) s.iterations = r.integer(solver["iterations"], "solver.iterations");
    s.damping = r.optNumber(solver, "damping", "solver", s.damping);
    s.maxSpeed = r.optNumber(solver, "max_speed", "solver", s.maxSpeed);
    s.gravity = doc.contains("gravity") ? r.vec3(doc["gravity"], "gravity") : Vec3::Zero();
    if (auto why = validate(s); !why.empty()) r.fail("solver", why);

    if (doc.contains("instructions")) scene.instructions = r.string(doc["instructions"], "instructions");
    const json& bodies = r.require(doc, "bodies", "");
    if (!bodies.is_array() || bodies.empty()) r.fail("bodies", "must be a non-empty array");
    std::set<std::string> names;
    for (size_t i = 0; i < bodies.size(); ++i) {
        const std::string p = "bodies[" + std::to_string(i) + "]";
        const json& b = bodies[i];
        BodyDesc body;
        body.name = r.string(r.require(b, "name", p), p + ".name");
        if (body.name.empty() || !names.insert(body.name).second)
            r.fail(p + ".name", "must be non-empty and unique");
        body.meshPath = r.string(r.require(b, "mesh", p), p + ".mesh");
        const json& m = r.require(b, "material", p);
        const std::string mp = p + ".material";
        try {
            body.material.model = materialModelFromName(r.string(r.require(m, "model", mp), mp + ".model"));
        } catch (const std::invalid_argument& e) {
            r.fail(mp + ".model", e.what());
        }
        body.material.youngsModulus = r.number(r.require(m, "youngs_modulus", mp), mp + ".youngs_modulus");
        body.material.poissonRatio = r.number(r.require(m, "poisson_ratio", mp), mp + ".poisson_ratio");
        body.material.density = r.number(r.require(m, "density", mp), mp + ".density");
        if (auto why = validate(body.material); !why.empty()) r.fail(mp, why);
        if (b.contains("fixed_nodes")) {
            const json& f = b["fixed_nodes"];
            if (!f.is_array()) r.fail(p + ".fixed_nodes", "must be an array of vertex indices");
            for (size_t k = 0; k < f.size(); ++k) {
                int v = r.integer(f[k], p + ".fixed_nodes[" + std::to_string(k) + "]");
                if (v < 0) r.fail(p + ".fixed_nodes[" + std::to_string(k) + "]", "must be non-negative");
                body.fixedNodes.push_back(v);
            }
        }
        scene.bodies.push_back(std::move(body));
    }
    return scene;
}

std::string formatScene(const SceneDesc& scene) {
    json doc;
    const XpbdSettings& s = scene.xpbd;
    doc["solver"] = {{"type", scene.solverType}, {"dt", s.dt},           {"substeps", s.substeps},
                     {"iterations", s.iterations}, {"damping", s.damping}, {"max_speed", s.maxSpeed}};
    doc["gravity"] = {s.gravity.x(), s.gravity.y(), s.gravity.z()};
    if (!scene.instructions.empty()) doc["instructions"] = scene.instructions;
    doc["bodies"] = json::array();
    for (const BodyDesc& b : scene.bodies) {
        doc["bodies"].push_back({{"name", b.name},
                                 {"mesh", b.meshPath},
                                 {"material",
                                  {{"model", materialModelName(b.material.model)},
                                   {"youngs_modulus", b.material.youngsModulus},
                                   {"poisson_ratio", b.material.poissonRatio},
                                   {"density", b.material.density}}},
                                 {"fixed_nodes", b.fixedNodes}});
    }
    return doc.dump(2) + "\n";
}

} // namespace viscera::sim
