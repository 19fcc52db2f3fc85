#include "sim/scene/assessment.hpp"
#include "sim/scene/scene.hpp"
#include "sim/scene/scene_json.hpp"

#include <algorithm>
#include <set>

namespace viscera::sim {

using nlohmann::json;

const std::vector<MetricInfo>& metricCatalogue() {
    static const std::vector<MetricInfo> k = {
        {"completion_time_s", "s", true, "simulated time at which every task target is met; none when never met"},
        {"path_length_m", "m", true, "distance travelled by the instruments' tips, summed over the instruments"},
        {"path_length_left_m", "m", true, "the same for the instruments of the left hand"},
        {"path_length_right_m", "m", true, "the same for the instruments of the right hand"},
        {"angular_path_rad", "rad", true, "angle swept by the instruments' shafts, summed over the instruments"},
        {"economy_of_motion", "ratio", false, "the case's reference path over the instruments' path length"},
        {"jerk_rms_m_s3", "m/s³", true,
         "root mean square of the tips' third time derivative while they move (smoothness)"},
        {"idle_time_s", "s", true,
         "time from the first movement until the targets are met (or the end) with no instrument tip moving faster "
         "than 2 mm/s"},
        {"instrument_collisions", "count", true, "times two instruments' tips came closer than their radii plus 2 mm"},
        {"out_of_view_s", "s", true,
         "time an instrument in use (its tip moved over 1 mm within half a second) was outside the laparoscope's "
         "round field of view (fov_deg across)"},
        {"force_mean_n", "N", true, "mean tissue force on the instruments over the samples in contact (> 0.01 N)"},
        {"force_max_n", "N", true, "largest tissue force on any instrument"},
        {"force_over_threshold_s", "s", true,
         "time any instrument's tissue force exceeded its damage threshold (the tool's damage_force_n where it "
         "declares one, else the case's force_threshold_n)"},
        {"tissue_damage_ns", "N·s", true,
         "integral over time of the tissue force above that threshold, summed over the tools"},
        {"cut_coverage", "fraction", false,
         "fraction of the marked lines' length within 1 mm of the hook's path through its cuts inside their radius "
         "(cuts up to 6 mm apart are one pass)"},
        {"cut_outside_edges", "count", true, "tissue edges cut farther than the radius from every marked line"},
        {"clips_on_target", "count", false, "clips applied within the tolerance of a clip target"},
        {"clips_off_target", "count", true, "clips applied away from every clip target"},
        {"bites", "count", false, "needle bites across the wound with their depth within the target's range"},
        {"bites_missed", "count", true,
         "passes through one wall (two punctures) that made no bite across the wound, or bites out of depth"},
        {"bite_spacing_error_m", "m", true, "largest distance of a spacing between successive bites outside its range"},
        {"vessel_injury_s", "s", true,
         "time the energized hook's tip was within the margin of the vessel to protect (targets.vessel)"},
        {"final_gap_m", "m", true, "largest gap between the wound's edges at the end"},
        {"max_thread_tension_n", "N", true, "largest tension of the thread"},
    };
    return k;
}

const MetricInfo* findMetric(std::string_view name) {
    for (const MetricInfo& m : metricCatalogue())
        if (m.name == name) return &m;
    return nullptr;
}

const MetricLevel* AssessmentDesc::level(std::string_view name) const {
    for (const MetricLevel& m : metrics)
        if (m.name == name) return &m;
    return nullptr;
}

namespace {

void readCutTargets(const JsonField& cuts, AssessmentDesc& a) {
    for (const JsonField& c : cuts.items(1, 16)) {
        c.object({"line", "radius", "coverage"});
        CutTarget t;
        for (const JsonField& p : c["line"].items(2, 256))
            t.line.push_back(p.vec3());
        double length = 0;
        for (size_t i = 1; i < t.line.size(); ++i)
            length += (t.line[i] - t.line[i - 1]).norm();
        if (!(length > 1e-4)) c.failAt("line", "must be at least 0.1 mm long");
        t.radius = c.number("radius", t.radius, NumberRule::aboveUpTo(0, 0.05));
        t.coverage = c.number("coverage", t.coverage, NumberRule::aboveUpTo(0, 1));
        a.cuts.push_back(std::move(t));
    }
}

void readClipTargets(const JsonField& clips, AssessmentDesc& a) {
    for (const JsonField& c : clips.items(1, 16)) {
        c.object({"position", "tolerance", "count"});
        ClipTarget t;
        t.position = c["position"].vec3();
        t.tolerance = c.number("tolerance", t.tolerance, NumberRule::aboveUpTo(0, 0.05));
        t.count = c.integer("count", t.count, 1, 16);
        a.clips.push_back(t);
    }
}

SutureTarget readSutureTarget(const JsonField& s) {
    s.object({"plane", "bites", "depth", "spacing", "max_gap"});
    SutureTarget t;
    const JsonField plane = s["plane"];
    plane.object({"point", "normal"});
    t.planePoint = plane["point"].vec3();
    const Vec3 n = plane["normal"].vec3();
    if (!(n.norm() > 1e-9)) plane.failAt("normal", "must not be zero");
    t.planeNormal = n.normalized();
    t.bites = s.integer("bites", t.bites, 1, 64);
    auto range = [&](std::string_view key, double& lo, double& hi) {
        const auto f = s.find(key);
        if (!f) return;
        const std::vector<JsonField> v = f->items(2, 2);
        lo = v[0].number(NumberRule::nonNegative());
        hi = v[1].number(NumberRule::aboveUpTo(0, 0.1));
        if (!(lo < hi)) f->fail("must be [min, max] with min < max");
    };
    range("depth", t.depthMin, t.depthMax);
    range("spacing", t.spacingMin, t.spacingMax);
    t.maxGap = s.number("max_gap", t.maxGap, NumberRule::aboveUpTo(0, 0.05));
    return t;
}

void readMetricLevels(const JsonField& metrics, AssessmentDesc& a) {
    std::vector<MetricLevel> levels;
    for (const auto& [name, m] : metrics.members()) {
        if (!findMetric(name)) m.fail("is not a metric the player measures (see the trainee guide's list)");
        m.object({"limit", "expert"});
        MetricLevel level{name, {}, {}};
        // Every metric is a time, length, angle, force, count or fraction: none is negative.
        if (auto l = m.find("limit")) level.limit = l->number(NumberRule::nonNegative());
        if (auto e = m.find("expert")) {
            e->object({"mean", "sd"});
            level.expert = ExpertLevel{(*e)["mean"].number(NumberRule::nonNegative()),
                                       (*e)["sd"].number(NumberRule::nonNegative())};
        }
        if (!level.limit && !level.expert) m.fail("needs a limit, an expert level or both");
        levels.push_back(level);
    }
    for (const MetricInfo& info : metricCatalogue()) // catalogue order
        for (const MetricLevel& l : levels)
            if (l.name == info.name) a.metrics.push_back(l);
}

/// A metric measured against a target needs that target in the block.
void checkMetricsHaveTheirTargets(const JsonField& metrics, const AssessmentDesc& a) {
    auto need = [&](std::initializer_list<std::string_view> names, bool has, const char* what) {
        for (std::string_view n : names)
            if (a.level(n) && !has) metrics.failAt(n, std::string("needs ") + what);
    };
    need({"completion_time_s"}, a.hasTargets(), "a target (targets.cut, targets.clip or targets.suture)");
    need({"cut_coverage", "cut_outside_edges"}, !a.cuts.empty(), "a cut target (targets.cut)");
    need({"clips_on_target", "clips_off_target"}, !a.clips.empty(), "a clip target (targets.clip)");
    need({"bites", "bites_missed", "bite_spacing_error_m"}, a.suture.has_value(), "a suture target (targets.suture)");
    need({"economy_of_motion"}, a.referencePathM.has_value(), "reference_path_m");
    need({"vessel_injury_s"}, a.vessel.has_value(), "a vessel to protect (targets.vessel)");
}

json vec(const Vec3& v) {
    return {v.x(), v.y(), v.z()};
}

} // namespace

AssessmentDesc readAssessment(const JsonField& block) {
    block.object({"targets", "force_threshold_n", "reference_path_m", "metrics"});
    AssessmentDesc a;
    if (auto targets = block.find("targets")) {
        targets->object({"cut", "clip", "suture", "vessel"});
        if (auto v = targets->find("vessel")) {
            v->object({"body", "margin"});
            a.vessel = VesselTarget{(*v)["body"].nonEmptyString()};
            a.vessel->margin = v->number("margin", a.vessel->margin, NumberRule::aboveUpTo(0, 0.02));
        }
        if (auto c = targets->find("cut")) readCutTargets(*c, a);
        if (auto c = targets->find("clip")) readClipTargets(*c, a);
        if (auto s = targets->find("suture")) a.suture = readSutureTarget(*s);
    }
    a.forceThresholdN = block.number("force_threshold_n", a.forceThresholdN, NumberRule::aboveUpTo(0, 50));
    if (auto r = block.find("reference_path_m")) a.referencePathM = r->number(NumberRule::aboveUpTo(0, 100));
    if (auto m = block.find("metrics")) {
        readMetricLevels(*m, a);
        checkMetricsHaveTheirTargets(*m, a);
    }
    return a;
}

void writeAssessment(const AssessmentDesc& a, json& doc) {
    json& j = doc["assessment"];
    j = json::object();
    for (const CutTarget& c : a.cuts) {
        json line = json::array();
        for (const Vec3& p : c.line)
            line.push_back(vec(p));
        j["targets"]["cut"].push_back({{"line", line}, {"radius", c.radius}, {"coverage", c.coverage}});
    }
    for (const ClipTarget& c : a.clips)
        j["targets"]["clip"].push_back({{"position", vec(c.position)}, {"tolerance", c.tolerance}, {"count", c.count}});
    if (const auto& v = a.vessel) j["targets"]["vessel"] = {{"body", v->body}, {"margin", v->margin}};
    if (const auto& s = a.suture)
        j["targets"]["suture"] = {{"plane", {{"point", vec(s->planePoint)}, {"normal", vec(s->planeNormal)}}},
                                  {"bites", s->bites},
                                  {"depth", {s->depthMin, s->depthMax}},
                                  {"spacing", {s->spacingMin, s->spacingMax}},
                                  {"max_gap", s->maxGap}};
    j["force_threshold_n"] = a.forceThresholdN;
    if (a.referencePathM) j["reference_path_m"] = *a.referencePathM;
    for (const MetricLevel& m : a.metrics) {
        json& e = j["metrics"][m.name];
        e = json::object();
        if (m.limit) e["limit"] = *m.limit;
        if (m.expert) e["expert"] = {{"mean", m.expert->mean}, {"sd", m.expert->sd}};
    }
}

std::vector<std::string> unmeasurableMetrics(const AssessmentDesc& a, const SceneDesc& scene,
                                             const std::vector<std::string>& bodies) {
    std::vector<std::string> problems;
    if (const auto& v = a.vessel; v && std::find(bodies.begin(), bodies.end(), v->body) == bodies.end())
        problems.push_back("assessment.targets.vessel.body: '" + v->body + "' is not a body of the scene");
    int tools = 0;
    bool left = false, right = false, ported = false;
    auto tool = [&](const std::string& hand, bool port) {
        ++tools, left |= hand == "left", right |= hand == "right", ported |= port;
    };
    if (scene.interaction)
        for (const InstrumentDesc& in : scene.interaction->instruments)
            tool(in.device.hand, in.port.declared);
    for (const ToolDesc& t : scene.tools)
        tool(t.hand, t.port.declared);
    if (scene.suture) tool(scene.suture->device.hand, false);
    const bool gauge = scene.suture && !scene.suture->gauge[0].empty();
    // What each metric needs of the scene; the tip metrics need any tool.
    const std::pair<std::string_view, std::pair<bool, const char*>> rules[] = {
        {"out_of_view_s", {scene.laparoscope.has_value(), "a laparoscope"}},
        {"instrument_collisions", {tools >= 2, "two tools"}},
        {"path_length_left_m", {left, "a tool in the left hand"}},
        {"path_length_right_m", {right, "a tool in the right hand"}},
        {"angular_path_rad", {ported, "an instrument or probe through a port"}},
        {"final_gap_m", {gauge, "a suture with a gauge"}},
        {"max_thread_tension_n", {scene.suture.has_value(), "a suture"}},
        {"path_length_m", {tools > 0, "a tool"}},
        {"economy_of_motion", {tools > 0, "a tool"}},
        {"jerk_rms_m_s3", {tools > 0, "a tool"}},
        {"idle_time_s", {tools > 0, "a tool"}},
        {"force_mean_n", {tools > 0, "a tool"}},
        {"force_max_n", {tools > 0, "a tool"}},
        {"force_over_threshold_s", {tools > 0, "a tool"}},
        {"tissue_damage_ns", {tools > 0, "a tool"}},
    };
    for (const MetricLevel& m : a.metrics) // catalogue order
        for (const auto& [name, rule] : rules)
            if (m.name == name && !rule.first)
                problems.push_back("assessment.metrics." + m.name + ": needs " + rule.second +
                                   " (this scene has none: no session could measure it)");
    return problems;
}

} // namespace viscera::sim
