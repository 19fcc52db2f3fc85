#include "sim/scene/scene_json.hpp"
#include "sim/util/error.hpp"

#include <nlohmann/json.hpp>

namespace viscera::sim {
namespace {

using nlohmann::json;

CurveDesc readCurve(const JsonField& c) {
    c.object({"points", "unconstrained"});
    CurveDesc d;
    const JsonField points = c["points"];
    if (!points.value().is_array() || points.value().size() < 2)
        points.fail("must be an array of at least 2 [x, y] pairs");
    for (const JsonField& p : points.items()) {
        if (!p.value().is_array() || p.value().size() != 2) p.fail("must be an [x, y] pair of numbers");
        const std::vector<JsonField> xy = p.items();
        d.points.push_back({xy[0].number(), xy[1].number()});
    }
    d.unconstrained = c.boolean("unconstrained", false);
    return d;
}

json curveJson(const CurveDesc& d) {
    json pts = json::array();
    for (const auto& p : d.points)
        pts.push_back({p[0], p[1]});
    json j = {{"points", pts}};
    if (d.unconstrained) j["unconstrained"] = true;
    return j;
}

} // namespace

Material readMaterial(const JsonField& j) {
    j.object({"model", "youngs_modulus", "poisson_ratio", "density", "curves"});
    Material m;
    const JsonField model = j["model"];
    try {
        m.model = materialModelFromName(model.string());
    } catch (const std::invalid_argument& e) {
        model.fail(e.what());
    }
    using L = MaterialLimits;
    m.youngsModulus = j["youngs_modulus"].number(NumberRule::aboveUpTo(0, L::maxYoungsModulus));
    m.poissonRatio = j["poisson_ratio"].number(NumberRule::fromBelow(0, L::maxPoissonRatio));
    m.density = j["density"].number(NumberRule::aboveUpTo(0, L::maxDensity));
    if (auto c = j.find("curves")) {
        c->object({"preset", "f_prime", "g_prime", "h_prime"});
        if (auto p = c->find("preset")) m.curvePreset = p->string();
        if (auto f = c->find("f_prime")) m.fPrime = readCurve(*f);
        if (auto g = c->find("g_prime")) m.gPrime = readCurve(*g);
        if (auto h = c->find("h_prime")) m.hPrime = readCurve(*h);
    }
    if (auto why = validate(m); !why.empty()) j.fail(why);
    return m;
}

json materialJson(const Material& m) {
    json j = {{"model", materialModelName(m.model)},
              {"youngs_modulus", m.youngsModulus},
              {"poisson_ratio", m.poissonRatio},
              {"density", m.density}};
    if (m.model == MaterialModel::ValanisLandel) {
        json c = json::object();
        if (!m.curvePreset.empty()) c["preset"] = m.curvePreset;
        if (m.fPrime) c["f_prime"] = curveJson(*m.fPrime);
        if (m.gPrime) c["g_prime"] = curveJson(*m.gPrime);
        if (m.hPrime) c["h_prime"] = curveJson(*m.hPrime);
        j["curves"] = c;
    }
    return j;
}

} // namespace viscera::sim
