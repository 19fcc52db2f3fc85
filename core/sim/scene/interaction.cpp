#include "sim/scene/interaction.hpp"

#include "sim/collision/collision_solver.hpp"
#include "sim/scene/scene_json.hpp"
#include "sim/util/error.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <set>

namespace viscera::sim {

using nlohmann::json;

const char* kindName(InstrumentDesc::Kind k) {
    switch (k) {
    case InstrumentDesc::Kind::Grasper:
        return "grasper";
    case InstrumentDesc::Kind::EnergyHook:
        return "energy_hook";
    case InstrumentDesc::Kind::ClipApplier:
        return "clip_applier";
    case InstrumentDesc::Kind::Scissors:
        return "scissors";
    case InstrumentDesc::Kind::NeedleDriver:
        return "needle_driver";
    }
    return "?";
}

InteractionDesc readInteractionSection(const JsonField& doc) {
    doc.object({"collision", "instruments", "tissues"});
    InteractionDesc d;
    if (auto c = doc.find("collision")) {
        c->object({"method", "delta", "bare_body"});
        if (auto m = c->find("method")) {
            d.collisionMethod = m->nonEmptyString();
            CollisionMethod method;
            if (!parseCollisionMethod(d.collisionMethod, method))
                m->fail("'" + d.collisionMethod + "' is not a method (" + kCollisionMethodNames + ")");
        }
        d.delta = c->number("delta", d.delta, NumberRule::closed(0.0, 10.0));
        d.bareBody = c->boolean("bare_body", d.bareBody);
    }
    std::set<std::string> names;
    for (const JsonField& j : doc["instruments"].items(1, 8)) {
        j.object({"name", "kind", "track", "radius", "jaw_length", "temperature_c", "target", "device", "port"});
        InstrumentDesc in;
        in.name = readName(j["name"], names); // it names the track file of the case
        const std::string kind =
            j["kind"].choice({"grasper", "energy_hook", "clip_applier", "scissors", "needle_driver"}, "an instrument");
        for (InstrumentDesc::Kind k :
             {InstrumentDesc::Kind::Grasper, InstrumentDesc::Kind::EnergyHook, InstrumentDesc::Kind::ClipApplier,
              InstrumentDesc::Kind::Scissors, InstrumentDesc::Kind::NeedleDriver})
            if (kind == kindName(k)) in.kind = k;
        in.trackPath = j["track"].entryPath();
        in.radius = j.number("radius", in.radius, NumberRule::closed(2e-4, 0.02));
        in.jawLength = j.number("jaw_length", in.jawLength, NumberRule::closed(1e-3, 0.05));
        if (j.has("temperature_c") && in.kind != InstrumentDesc::Kind::EnergyHook)
            j.failAt("temperature_c", "only an energy_hook has a temperature");
        in.temperatureC = j.number("temperature_c", in.temperatureC, NumberRule::closed(40, 400));
        if (in.kind == InstrumentDesc::Kind::ClipApplier)
            in.target = j["target"].nonEmptyString();
        else if (j.has("target"))
            j.failAt("target", "only a clip_applier has a target");
        if (auto dev = j.find("device")) {
            dev->object({"hand", "motion_scale", "force_scale", "max_force_n", "damage_force_n", "grip_open_rad"});
            InstrumentDeviceDesc& dd = in.device;
            readDeviceMapping(*dev, dd);
            if (auto f = dev->find("damage_force_n")) dd.damageForceN = f->number(NumberRule::aboveUpTo(0, 1000.0));
            dd.gripOpenRad = dev->number("grip_open_rad", dd.gripOpenRad, NumberRule::closed(0.05, M_PI));
        }
        if (auto port = j.find("port")) readPort(*port, in.port);
        d.instruments.push_back(std::move(in));
    }
    if (auto t = doc.find("tissues")) {
        std::set<std::string> layers;
        for (const JsonField& tj : t->items()) {
            tj.object({"layer", "ignition_c", "conductivity", "shrink"});
            DissectionTissueDesc ti;
            const JsonField layer = tj["layer"];
            ti.layer = layer.nonEmptyString();
            if (!layers.insert(ti.layer).second) layer.fail("'" + ti.layer + "' is listed twice");
            ti.ignitionC = tj.number("ignition_c", ti.ignitionC, NumberRule::closed(40, 400));
            ti.conductivity = tj.number("conductivity", ti.conductivity, NumberRule::closed(1e-6, 10));
            if (auto s = tj.find("shrink")) ti.shrink = s->vec3(NumberRule::aboveUpTo(0, 1));
            d.tissues.push_back(ti);
        }
    }
    if (d.has(InstrumentDesc::Kind::EnergyHook) && d.tissues.empty())
        doc.failAt("tissues", "an energy_hook needs at least one tissue with an ignition temperature");
    if (d.has(InstrumentDesc::Kind::Scissors) && d.tissues.empty())
        doc.failAt("tissues", "scissors need at least one tissue to cut");
    return d;
}

InteractionDesc parseInteractionSection(std::string_view text, const std::string& origin) {
    const json doc = parseJsonText(text, origin);
    return readInteractionSection(JsonField(doc, "interaction", origin));
}

void checkInteractionNames(const InteractionDesc& d, const std::vector<std::string>& bodies,
                           const std::vector<std::string>& surfaces, const std::string& origin) {
    auto fail = [&](const std::string& field, const std::string& rule) {
        throw InputError(origin + ": interaction." + field + ": " + rule);
    };
    auto in = [](const std::vector<std::string>& v, const std::string& n) {
        return std::find(v.begin(), v.end(), n) != v.end();
    };
    for (size_t i = 0; i < d.instruments.size(); ++i)
        if (d.instruments[i].kind == InstrumentDesc::Kind::ClipApplier && !in(bodies, d.instruments[i].target))
            fail("instruments[" + std::to_string(i) + "].target",
                 "'" + d.instruments[i].target + "' is not a body of the scene");
    for (size_t i = 0; i < d.tissues.size(); ++i)
        if (!in(bodies, d.tissues[i].layer) && !in(surfaces, d.tissues[i].layer))
            fail("tissues[" + std::to_string(i) + "].layer",
                 "'" + d.tissues[i].layer + "' is not a body or surface of the scene");
}

json interactionJson(const InteractionDesc& d) {
    json doc;
    doc["collision"] = {{"method", d.collisionMethod}, {"delta", d.delta}};
    if (d.bareBody) doc["collision"]["bare_body"] = true;
    doc["instruments"] = json::array();
    for (const InstrumentDesc& in : d.instruments) {
        json j = {{"name", in.name},
                  {"kind", kindName(in.kind)},
                  {"track", in.trackPath},
                  {"radius", in.radius},
                  {"jaw_length", in.jawLength}};
        if (in.kind == InstrumentDesc::Kind::EnergyHook) j["temperature_c"] = in.temperatureC;
        if (in.kind == InstrumentDesc::Kind::ClipApplier) j["target"] = in.target;
        if (in.device.declared) {
            const InstrumentDeviceDesc& dd = in.device;
            writeDeviceMapping(dd, j["device"]);
            if (dd.damageForceN) j["device"]["damage_force_n"] = *dd.damageForceN;
            j["device"]["grip_open_rad"] = dd.gripOpenRad;
        }
        if (in.port.declared) writePort(in.port, j["port"]);
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
    return doc;
}

std::string formatInteractionSection(const InteractionDesc& d) {
    return interactionJson(d).dump();
}

} // namespace viscera::sim
