#include "sim/suture/suture_scene.hpp"

#include "sim/util/error.hpp"
#include "sim/util/json_section.hpp"

#include <nlohmann/json.hpp>

#include <cmath>

namespace viscera::sim::suture {
namespace {

using nlohmann::json;

struct Reader : detail::SectionReader {
    double positive(const json& obj, const char* key, const std::string& path, double def) const {
        auto it = obj.find(key);
        if (it == obj.end()) return def;
        if (!it->is_number() || !std::isfinite(it->get<double>()) || !(it->get<double>() > 0))
            fail(path + "." + key, "must be a positive number");
        return it->get<double>();
    }
    int integer(const json& obj, const char* key, const std::string& path, int def, int lo, int hi) const {
        auto it = obj.find(key);
        if (it == obj.end()) return def;
        if (!it->is_number_integer() || it->get<int64_t>() < lo || it->get<int64_t>() > hi)
            fail(path + "." + key, "must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
        return static_cast<int>(it->get<int64_t>());
    }
};

} // namespace

SutureSceneDesc parseSutureSection(std::string_view text, const std::string& origin) {
    const Reader r{{origin, "suture"}};
    const json doc = json::parse(text, nullptr, false);
    if (doc.is_discarded()) throw InputError(origin + ": suture: not valid JSON");
    r.only(doc, {"needle", "thread", "contact", "trajectory", "gauge"}, "");
    SutureSceneDesc d;
    SutureSettings& s = d.settings;
    if (!doc.contains("needle")) r.fail("needle", "required field is missing");
    const json& n = doc["needle"];
    r.only(n, {"shape", "radius", "length", "handle", "puncture_force_n"}, "needle");
    if (n.contains("shape")) {
        if (!n["shape"].is_string()) r.fail("needle.shape", "must be 'semicircle' or 'straight'");
        const std::string shape = n["shape"].get<std::string>();
        if (shape == "semicircle") s.needle.shape = NeedleSpec::Shape::Semicircle;
        else if (shape == "straight") s.needle.shape = NeedleSpec::Shape::Straight;
        else r.fail("needle.shape", "'" + shape + "' is not a needle shape (semicircle, straight)");
    }
    s.needle.radius = r.positive(n, "radius", "needle", s.needle.radius);
    s.needle.length = r.positive(n, "length", "needle", s.needle.length);
    if (n.contains("handle")) {
        if (!n["handle"].is_number() || !(n["handle"].get<double>() >= 0)) r.fail("needle.handle", "must be a number >= 0");
        s.needle.handle = n["handle"].get<double>();
    }
    s.needle.punctureForce = r.positive(n, "puncture_force_n", "needle", s.needle.punctureForce);
    if (doc.contains("thread")) {
        const json& t = doc["thread"];
        r.only(t, {"length", "slack", "stabilization", "max_strain_per_step"}, "thread");
        d.thread = true;
        s.thread.length = r.positive(t, "length", "thread", s.thread.length);
        if (t.contains("slack")) {
            if (!t["slack"].is_number() || !(t["slack"].get<double>() >= 0)) r.fail("thread.slack", "must be a number >= 0");
            s.thread.slack = t["slack"].get<double>();
        }
        s.thread.stabilization = r.positive(t, "stabilization", "thread", s.thread.stabilization);
        s.thread.maxStrainPerStep = r.positive(t, "max_strain_per_step", "thread", s.thread.maxStrainPerStep);
    }
    d.contact = doc.contains("contact");
    s.contact = d.contact;
    if (d.contact) {
        const json& c = doc["contact"];
        r.only(c, {"thickness", "rounds", "per_round", "max"}, "contact");
        s.contactThickness = r.positive(c, "thickness", "contact", s.contactThickness);
        s.contactRounds = r.integer(c, "rounds", "contact", s.contactRounds, 0, 16);
        s.contactsPerRound = r.integer(c, "per_round", "contact", s.contactsPerRound, 1, 4096);
        s.maxContacts = r.integer(c, "max", "contact", s.maxContacts, 1, 4096);
    }
    if (!doc.contains("trajectory") || !doc["trajectory"].is_string() || doc["trajectory"].get<std::string>().empty())
        r.fail("trajectory", "required: the path of the needle trajectory file inside the case");
    d.trajectoryPath = doc["trajectory"].get<std::string>();
    if (doc.contains("gauge")) {
        const json& g = doc["gauge"];
        if (!g.is_array() || g.size() != 2 || !g[0].is_string() || !g[1].is_string() || g[0] == g[1])
            r.fail("gauge", "must name two different bodies");
        d.gauge = {g[0].get<std::string>(), g[1].get<std::string>()};
    }
    if (auto why = validate(s); !why.empty()) r.fail("needle", why);
    return d;
}

std::string formatSutureSection(const SutureSceneDesc& d) {
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
    return doc.dump();
}

} // namespace viscera::sim::suture
