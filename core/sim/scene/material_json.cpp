#include "sim/scene/material_json.hpp"

#include "sim/util/error.hpp"

#include <nlohmann/json.hpp>

#include <cmath>

namespace viscera::sim {
namespace {

using nlohmann::json;

[[noreturn]] void fail(const std::string& origin, const std::string& field, const std::string& rule) {
    throw InputError(origin + ": " + field + ": " + rule);
}

double number(const json& obj, const char* key, const std::string& path, const std::string& origin) {
    auto it = obj.find(key);
    if (it == obj.end()) fail(origin, path + "." + key, "required field is missing");
    if (!it->is_number() || !std::isfinite(it->get<double>())) fail(origin, path + "." + key, "must be a finite number");
    return it->get<double>();
}

CurveDesc parseCurve(const json& c, const std::string& path, const std::string& origin) {
    if (!c.is_object()) fail(origin, path, "must be an object with \"points\"");
    for (auto it = c.begin(); it != c.end(); ++it)
        if (it.key() != "points" && it.key() != "unconstrained") fail(origin, path + "." + it.key(), "unknown field");
    CurveDesc d;
    auto pts = c.find("points");
    if (pts == c.end() || !pts->is_array() || pts->size() < 2)
        fail(origin, path + ".points", "must be an array of at least 2 [x, y] pairs");
    for (size_t i = 0; i < pts->size(); ++i) {
        const json& p = (*pts)[i];
        const std::string pp = path + ".points[" + std::to_string(i) + "]";
        if (!p.is_array() || p.size() != 2 || !p[0].is_number() || !p[1].is_number())
            fail(origin, pp, "must be an [x, y] pair of numbers");
        d.points.push_back({p[0].get<double>(), p[1].get<double>()});
    }
    if (auto u = c.find("unconstrained"); u != c.end()) {
        if (!u->is_boolean()) fail(origin, path + ".unconstrained", "must be true or false");
        d.unconstrained = u->get<bool>();
    }
    return d;
}

json curveToJson(const CurveDesc& d) {
    json pts = json::array();
    for (const auto& p : d.points) pts.push_back({p[0], p[1]});
    json j = {{"points", pts}};
    if (d.unconstrained) j["unconstrained"] = true;
    return j;
}

} // namespace

Material parseMaterial(const json& j, const std::string& path, const std::string& origin) {
    if (!j.is_object()) fail(origin, path, "must be an object");
    for (auto it = j.begin(); it != j.end(); ++it) {
        const std::string& k = it.key();
        if (k != "model" && k != "youngs_modulus" && k != "poisson_ratio" && k != "density" && k != "curves")
            fail(origin, path + "." + k, "unknown field");
    }
    Material m;
    auto model = j.find("model");
    if (model == j.end()) fail(origin, path + ".model", "required field is missing");
    if (!model->is_string()) fail(origin, path + ".model", "must be a string");
    try {
        m.model = materialModelFromName(model->get<std::string>());
    } catch (const std::invalid_argument& e) {
        fail(origin, path + ".model", e.what());
    }
    m.youngsModulus = number(j, "youngs_modulus", path, origin);
    m.poissonRatio = number(j, "poisson_ratio", path, origin);
    m.density = number(j, "density", path, origin);
    if (auto c = j.find("curves"); c != j.end()) {
        const std::string cp = path + ".curves";
        if (!c->is_object()) fail(origin, cp, "must be an object");
        for (auto it = c->begin(); it != c->end(); ++it) {
            const std::string& k = it.key();
            if (k == "preset") {
                if (!it->is_string()) fail(origin, cp + ".preset", "must be a string");
                m.curvePreset = it->get<std::string>();
            } else if (k == "f_prime") {
                m.fPrime = parseCurve(*it, cp + ".f_prime", origin);
            } else if (k == "g_prime") {
                m.gPrime = parseCurve(*it, cp + ".g_prime", origin);
            } else if (k == "h_prime") {
                m.hPrime = parseCurve(*it, cp + ".h_prime", origin);
            } else {
                fail(origin, cp + "." + k, "unknown field (preset, f_prime, g_prime, h_prime)");
            }
        }
    }
    if (auto why = validate(m); !why.empty()) fail(origin, path, why);
    return m;
}

json materialToJson(const Material& m) {
    json j = {{"model", materialModelName(m.model)},
              {"youngs_modulus", m.youngsModulus},
              {"poisson_ratio", m.poissonRatio},
              {"density", m.density}};
    if (m.model == MaterialModel::ValanisLandel) {
        json c = json::object();
        if (!m.curvePreset.empty()) c["preset"] = m.curvePreset;
        if (m.fPrime) c["f_prime"] = curveToJson(*m.fPrime);
        if (m.gPrime) c["g_prime"] = curveToJson(*m.gPrime);
        if (m.hPrime) c["h_prime"] = curveToJson(*m.hPrime);
        j["curves"] = c;
    }
    return j;
}

} // namespace viscera::sim
