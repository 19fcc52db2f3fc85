#include "sim/scene/interaction.hpp"

#include "sim/collision/collision_solver.hpp"
#include "sim/util/error.hpp"
#include "sim/util/json_section.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <set>

namespace viscera::sim {
namespace {

using nlohmann::json;

struct Reader : detail::SectionReader {
    double number(const json& obj, const char* key, const std::string& path, double def, double lo, double hi) const {
        auto it = obj.find(key);
        if (it == obj.end()) return def;
        if (!it->is_number() || !std::isfinite(it->get<double>()) || it->get<double>() < lo || it->get<double>() > hi)
            fail(path + "." + key, "must be a number in [" + fmt(lo) + ", " + fmt(hi) + "]");
        return it->get<double>();
    }
    std::string text(const json& obj, const char* key, const std::string& path) const {
        auto it = obj.find(key);
        if (it == obj.end()) fail(path + "." + key, "required field is missing");
        if (!it->is_string() || it->get<std::string>().empty()) fail(path + "." + key, "must be a non-empty string");
        return it->get<std::string>();
    }
};

} // namespace

const char* kindName(InstrumentDesc::Kind k) {
    switch (k) {
    case InstrumentDesc::Kind::Grasper: return "grasper";
    case InstrumentDesc::Kind::EnergyHook: return "energy_hook";
    case InstrumentDesc::Kind::ClipApplier: return "clip_applier";
    }
    return "?";
}

InteractionDesc parseInteractionSection(std::string_view text, const std::string& origin) {
    const Reader r{{origin, "interaction"}};
    const json doc = json::parse(text, nullptr, false);
    if (doc.is_discarded()) throw InputError(origin + ": interaction: not valid JSON");
    r.only(doc, {"collision", "instruments", "tissues"}, "");
    InteractionDesc d;
    if (doc.contains("collision")) {
        const json& c = doc["collision"];
        r.only(c, {"method", "delta"}, "collision");
        if (c.contains("method")) {
            d.collisionMethod = r.text(c, "method", "collision");
            CollisionMethod m;
            if (!parseCollisionMethod(d.collisionMethod, m))
                r.fail("collision.method", "'" + d.collisionMethod + "' is not a method (" + kCollisionMethodNames + ")");
        }
        d.delta = r.number(c, "delta", "collision", d.delta, 0.0, 10.0);
    }
    if (!doc.contains("instruments")) r.fail("instruments", "required field is missing");
    const json& list = doc["instruments"];
    if (!list.is_array() || list.empty() || list.size() > 8) r.fail("instruments", "must be an array of 1 to 8 instruments");
    std::set<std::string> names, tracks;
    for (size_t i = 0; i < list.size(); ++i) {
        const std::string p = "instruments[" + std::to_string(i) + "]";
        const json& j = list[i];
        r.only(j, {"name", "kind", "track", "radius", "jaw_length", "temperature_c", "target"}, p);
        InstrumentDesc in;
        in.name = r.text(j, "name", p);
        if (!names.insert(in.name).second) r.fail(p + ".name", "'" + in.name + "' is used twice");
        const std::string kind = r.text(j, "kind", p);
        if (kind == "grasper") in.kind = InstrumentDesc::Kind::Grasper;
        else if (kind == "energy_hook") in.kind = InstrumentDesc::Kind::EnergyHook;
        else if (kind == "clip_applier") in.kind = InstrumentDesc::Kind::ClipApplier;
        else r.fail(p + ".kind", "'" + kind + "' is not an instrument (grasper, energy_hook, clip_applier)");
        in.trackPath = r.text(j, "track", p);
        if (in.trackPath.front() == '/' || in.trackPath.find("..") != std::string::npos)
            r.fail(p + ".track", "must be a relative path inside the case");
        in.radius = r.number(j, "radius", p, in.radius, 2e-4, 0.02);
        in.jawLength = r.number(j, "jaw_length", p, in.jawLength, 1e-3, 0.05);
        if (j.contains("temperature_c") && in.kind != InstrumentDesc::Kind::EnergyHook)
            r.fail(p + ".temperature_c", "only an energy_hook has a temperature");
        in.temperatureC = r.number(j, "temperature_c", p, in.temperatureC, 40, 400);
        if (in.kind == InstrumentDesc::Kind::ClipApplier) in.target = r.text(j, "target", p);
        else if (j.contains("target")) r.fail(p + ".target", "only a clip_applier has a target");
        d.instruments.push_back(std::move(in));
    }
    if (doc.contains("tissues")) {
        const json& t = doc["tissues"];
        if (!t.is_array()) r.fail("tissues", "must be an array");
        std::set<std::string> layers;
        for (size_t i = 0; i < t.size(); ++i) {
            const std::string p = "tissues[" + std::to_string(i) + "]";
            r.only(t[i], {"layer", "ignition_c", "conductivity", "shrink"}, p);
            DissectionTissueDesc ti;
            ti.layer = r.text(t[i], "layer", p);
            if (!layers.insert(ti.layer).second) r.fail(p + ".layer", "'" + ti.layer + "' is listed twice");
            ti.ignitionC = r.number(t[i], "ignition_c", p, ti.ignitionC, 40, 400);
            ti.conductivity = r.number(t[i], "conductivity", p, ti.conductivity, 1e-6, 10);
            if (t[i].contains("shrink")) {
                const json& s = t[i]["shrink"];
                if (!s.is_array() || s.size() != 3) r.fail(p + ".shrink", "must be an array of 3 ratios in (0, 1]");
                for (int k = 0; k < 3; ++k) {
                    if (!s[k].is_number() || !(s[k].get<double>() > 0) || s[k].get<double>() > 1)
                        r.fail(p + ".shrink", "must be an array of 3 ratios in (0, 1]");
                    ti.shrink[k] = s[k].get<double>();
                }
            }
            d.tissues.push_back(ti);
        }
    }
    if (d.has(InstrumentDesc::Kind::EnergyHook) && d.tissues.empty())
        r.fail("tissues", "an energy_hook needs at least one tissue with an ignition temperature");
    return d;
}

void checkInteractionNames(const InteractionDesc& d, const std::vector<std::string>& bodies,
                           const std::vector<std::string>& surfaces, const std::string& origin) {
    const detail::SectionReader r{origin, "interaction"};
    auto in = [](const std::vector<std::string>& v, const std::string& n) { return std::find(v.begin(), v.end(), n) != v.end(); };
    for (size_t i = 0; i < d.instruments.size(); ++i)
        if (d.instruments[i].kind == InstrumentDesc::Kind::ClipApplier && !in(bodies, d.instruments[i].target))
            r.fail("instruments[" + std::to_string(i) + "].target", "'" + d.instruments[i].target + "' is not a body of the scene");
    for (size_t i = 0; i < d.tissues.size(); ++i)
        if (!in(bodies, d.tissues[i].layer) && !in(surfaces, d.tissues[i].layer))
            r.fail("tissues[" + std::to_string(i) + "].layer",
                   "'" + d.tissues[i].layer + "' is not a body or surface of the scene");
}

std::string formatInteractionSection(const InteractionDesc& d) {
    json doc;
    doc["collision"] = {{"method", d.collisionMethod}, {"delta", d.delta}};
    doc["instruments"] = json::array();
    for (const InstrumentDesc& in : d.instruments) {
        json j = {{"name", in.name}, {"kind", kindName(in.kind)}, {"track", in.trackPath}, {"radius", in.radius},
                  {"jaw_length", in.jawLength}};
        if (in.kind == InstrumentDesc::Kind::EnergyHook) j["temperature_c"] = in.temperatureC;
        if (in.kind == InstrumentDesc::Kind::ClipApplier) j["target"] = in.target;
        doc["instruments"].push_back(j);
    }
    if (!d.tissues.empty()) {
        doc["tissues"] = json::array();
        for (const DissectionTissueDesc& t : d.tissues)
            doc["tissues"].push_back({{"layer", t.layer},
                                      {"ignition_c", t.ignitionC},
                                      {"conductivity", t.conductivity},
                                      {"shrink", {t.shrink.x(), t.shrink.y(), t.shrink.z()}}});
    }
    return doc.dump();
}

} // namespace viscera::sim
