#include "sim/suture/suture_scene.hpp"

#include "sim/scene/scene_json.hpp"
#include "sim/util/error.hpp"

#include <nlohmann/json.hpp>

namespace viscera::sim {

using nlohmann::json;

SutureSceneDesc readSutureSection(const JsonField& doc, bool readTrajectory) {
    doc.object({"needle", "thread", "contact", "trajectory", "gauge", "device"});
    SutureSceneDesc d;
    SutureSettings& s = d.settings;
    const JsonField n = doc["needle"];
    n.object({"shape", "radius", "length", "handle", "puncture_force_n"});
    if (auto shape = n.find("shape"))
        s.needle.shape = shape->choice({"semicircle", "straight"}, "a needle shape") == "semicircle"
                             ? NeedleSpec::Shape::Semicircle
                             : NeedleSpec::Shape::Straight;
    s.needle.radius = n.number("radius", s.needle.radius, NumberRule::positive());
    s.needle.length = n.number("length", s.needle.length, NumberRule::positive());
    s.needle.handle = n.number("handle", s.needle.handle, NumberRule::nonNegative());
    if (s.needle.handle > s.needle.length_()) n.failAt("handle", "must lie on the needle (at most its length)");
    s.needle.punctureForce = n.number("puncture_force_n", s.needle.punctureForce, NumberRule::positive());
    if (auto t = doc.find("thread")) {
        t->object({"length", "slack", "stabilization", "max_strain_per_step"});
        d.thread = true;
        s.thread.length = t->number("length", s.thread.length, NumberRule::positive());
        s.thread.slack = t->number("slack", s.thread.slack, NumberRule::nonNegative());
        s.thread.stabilization = t->number("stabilization", s.thread.stabilization, NumberRule::positive());
        s.thread.maxStrainPerStep =
            t->number("max_strain_per_step", s.thread.maxStrainPerStep, NumberRule{0, 1, true, true});
    }
    d.contact = doc.has("contact");
    s.contact = d.contact;
    if (auto c = doc.find("contact")) {
        c->object({"thickness", "rounds", "per_round", "max"});
        s.contactThickness = c->number("thickness", s.contactThickness, NumberRule::positive());
        s.contactRounds = c->integer("rounds", s.contactRounds, 0, 16);
        s.contactsPerRound = c->integer("per_round", s.contactsPerRound, 1, 4096);
        s.maxContacts = c->integer("max", s.maxContacts, 1, 4096);
    }
    if (readTrajectory) d.trajectoryPath = doc["trajectory"].entryPath();
    if (auto g = doc.find("gauge")) {
        const std::vector<JsonField> pair = g->items(2, 2);
        d.gauge = {pair[0].nonEmptyString(), pair[1].nonEmptyString()};
        if (d.gauge[0] == d.gauge[1]) g->fail("must name two different bodies");
    }
    if (auto dev = doc.find("device")) {
        dev->object({"hand", "motion_scale", "force_scale", "max_force_n", "pull_scale"});
        NeedleDeviceDesc& nd = d.device;
        readDeviceMapping(*dev, nd);
        nd.pullScale = dev->number("pull_scale", nd.pullScale, NumberRule::aboveUpTo(0, 10.0));
    }
    if (auto why = validate(s); !why.empty()) n.fail(why);
    return d;
}

json sutureJson(const SutureSceneDesc& d) {
    const SutureSettings& s = d.settings;
    json doc;
    doc["needle"] = {{"shape", s.needle.shape == NeedleSpec::Shape::Semicircle ? "semicircle" : "straight"},
                     {"radius", s.needle.radius},
                     {"length", s.needle.length},
                     {"handle", s.needle.handle},
                     {"puncture_force_n", s.needle.punctureForce}};
    if (d.thread)
        doc["thread"] = {{"length", s.thread.length},
                         {"slack", s.thread.slack},
                         {"stabilization", s.thread.stabilization},
                         {"max_strain_per_step", s.thread.maxStrainPerStep}};
    if (d.contact)
        doc["contact"] = {{"thickness", s.contactThickness},
                          {"rounds", s.contactRounds},
                          {"per_round", s.contactsPerRound},
                          {"max", s.maxContacts}};
    doc["trajectory"] = d.trajectoryPath;
    if (!d.gauge[0].empty()) doc["gauge"] = {d.gauge[0], d.gauge[1]};
    if (d.device.declared) {
        writeDeviceMapping(d.device, doc["device"]);
        doc["device"]["pull_scale"] = d.device.pullScale;
    }
    return doc;
}

} // namespace viscera::sim
