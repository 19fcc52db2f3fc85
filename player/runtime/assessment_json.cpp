#include "runtime/assessment_json.hpp"

#include <cmath>

namespace viscera::player {

namespace {

nlohmann::json numberOrNull(std::optional<double> v) {
    return v && std::isfinite(*v) ? nlohmann::json(*v) : nlohmann::json();
}

} // namespace

nlohmann::json assessmentJson(const Assessment& a) {
    using nlohmann::json;
    json metrics = json::array();
    for (const MetricResult& m : a.metrics) {
        json j = {{"name", m.name},
                  {"unit", m.unit},
                  {"value", numberOrNull(m.value)},
                  {"better", m.lowerIsBetter ? "lower" : "higher"},
                  {"limit", numberOrNull(m.limit)},
                  {"passed", m.passed},
                  {"expert", nullptr},
                  {"within_expert", nullptr}};
        if (m.expert) {
            j["expert"] = {{"mean", m.expert->mean}, {"sd", m.expert->sd}, {"bound", m.bound}};
            j["within_expert"] = *m.withinExpert;
        }
        metrics.push_back(j);
    }
    json tools = json::array();
    for (const ToolFigures& t : a.tools)
        tools.push_back({{"name", t.name},
                         {"kind", t.kind},
                         {"hand", t.hand},
                         {"path_m", t.pathM},
                         {"angular_path_rad", t.angularRad},
                         {"force_max_n", t.forceMaxN},
                         {"force_mean_n", t.forceMeanN},
                         {"force_over_threshold_s", t.overThresholdS},
                         {"tissue_damage_ns", t.damageNs}});
    return {{"judged", a.judged},
            {"passed", a.judged ? json(a.passed) : json()},
            {"completion_time_s", numberOrNull(a.completionS)},
            {"within_expert_level", a.withinExpertLevel()},
            {"metrics", metrics},
            {"tools", tools}};
}

MetricResult readMetricJson(const ReportReader& rd, const nlohmann::json& m, const std::string& f) {
    MetricResult out;
    out.name = rd.string(rd.member(m, f, "name"), f + ".name");
    if (out.name.empty() || out.name.size() > 64) rd.fail(f + ".name", "must be 1 to 64 characters");
    for (unsigned char c : out.name)
        if (c < 0x20) rd.fail(f + ".name", "must not contain control characters");
    out.unit = rd.string(rd.member(m, f, "unit"), f + ".unit");
    out.value = rd.numberOrNone(rd.member(m, f, "value"), f + ".value");
    const std::string better = rd.string(rd.member(m, f, "better"), f + ".better");
    if (better != "lower" && better != "higher") rd.fail(f + ".better", "must be \"lower\" or \"higher\"");
    out.lowerIsBetter = better == "lower";
    out.limit = rd.numberOrNone(rd.member(m, f, "limit"), f + ".limit");
    out.passed = rd.boolean(rd.member(m, f, "passed"), f + ".passed");
    const nlohmann::json& e = rd.member(m, f, "expert");
    if (!e.is_null()) {
        const std::string g = f + ".expert";
        sim::ExpertLevel x{rd.number(rd.member(e, g, "mean"), g + ".mean"),
                           rd.number(rd.member(e, g, "sd"), g + ".sd")};
        if (x.sd < 0) rd.fail(g + ".sd", "must not be negative");
        out.expert = x;
        out.bound = rd.number(rd.member(e, g, "bound"), g + ".bound");
    }
    const nlohmann::json& w = rd.member(m, f, "within_expert");
    if (!w.is_null()) {
        if (!out.expert) rd.fail(f + ".within_expert", "must be null when the metric has no expert level");
        out.withinExpert = rd.boolean(w, f + ".within_expert");
    } else if (out.expert && out.value) {
        rd.fail(f + ".within_expert", "must be true or false when the metric has a value and an expert level");
    } else if (out.expert) {
        out.withinExpert = false; // no value: not within
    }
    return out;
}

} // namespace viscera::player
