#include "runtime/assessment.hpp"

#include "runtime/session.hpp"
#include "sim/collision/distance.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <numbers>

namespace viscera::player {

namespace {

using Vec3 = Eigen::Vector3d;
constexpr double kIdleSpeed = 0.002;       ///< m/s: a tip slower than this is idle
constexpr double kContactForce = 0.01;     ///< N: a tool in contact
constexpr double kCollisionMargin = 0.002; ///< m, beyond the radii
constexpr double kCutHalfWidth = 0.001;    ///< m: a cut opens the marked line this far either side of the hook
constexpr double kCutPassGap = 0.006;      ///< m: successive cuts this close are one pass of the hook (edges ~2 mm)

bool finite(const Vec3& v) {
    return v.allFinite();
}

/// Seconds each timeline sample stands for (the time to the next sample; the last repeats).
std::vector<double> sampleSpans(const SessionTimeline& tl) {
    std::vector<double> w(tl.t_s.size(), 0.0);
    for (size_t i = 0; i + 1 < tl.t_s.size(); ++i)
        w[i] = tl.t_s[i + 1] - tl.t_s[i];
    if (w.size() > 1) w.back() = w[w.size() - 2];
    return w;
}

ToolFigures toolFigures(const SessionTimeline::Tool& t, const std::vector<double>& span, double threshold) {
    ToolFigures f{t.name, t.kind, t.hand};
    for (size_t i = 1; i < t.tip.size(); ++i)
        if (finite(t.tip[i]) && finite(t.tip[i - 1])) f.pathM += (t.tip[i] - t.tip[i - 1]).norm();
    for (size_t i = 1; i < t.axis.size(); ++i)
        if (finite(t.axis[i]) && finite(t.axis[i - 1]))
            f.angularRad += std::acos(std::clamp(t.axis[i].dot(t.axis[i - 1]), -1.0, 1.0));
    double sum = 0;
    int n = 0;
    for (size_t i = 0; i < t.force_n.size() && i < span.size(); ++i) {
        const double v = t.force_n[i];
        if (!std::isfinite(v)) continue;
        f.forceMaxN = std::max(f.forceMaxN, v);
        if (v > kContactForce) sum += v, ++n;
        if (v > threshold) f.overThresholdS += span[i], f.damageNs += (v - threshold) * span[i];
    }
    f.forceMeanN = n ? sum / n : 0.0;
    return f;
}

/// Time-ordered figures of the targets: when each was met and what was outside them.
struct TargetFigures {
    std::optional<double> metAt; ///< all targets met (none: not all)
    double cutCoverage = 1;      ///< the least covered cut target
    int cutOutside = 0, clipsOn = 0, clipsOff = 0;
    int bites = 0, bitesMissed = 0;
    double spacingError = 0;
};

double pointSegment(const Vec3& p, const Vec3& a, const Vec3& b) {
    const Vec3 ab = b - a;
    const double s = std::clamp((p - a).dot(ab) / std::max(ab.squaredNorm(), 1e-18), 0.0, 1.0);
    return (p - (a + s * ab)).norm();
}

double lineDistance(const Vec3& p, const std::vector<Vec3>& line) {
    double d = std::numeric_limits<double>::infinity();
    for (size_t i = 1; i < line.size(); ++i)
        d = std::min(d, pointSegment(p, line[i - 1], line[i]));
    return d;
}

/// The cut targets, in 0.5 mm bins along each line: a cut marks the bins within the radius.
struct CutCoverage {
    std::vector<std::vector<Vec3>> bins;
    std::vector<std::vector<char>> hit;
    explicit CutCoverage(const std::vector<sim::CutTarget>& cuts) {
        for (const sim::CutTarget& c : cuts) {
            std::vector<Vec3> b;
            for (size_t i = 1; i < c.line.size(); ++i) {
                const int n = std::max(1, int(std::ceil((c.line[i] - c.line[i - 1]).norm() / 0.0005)));
                for (int k = 0; k < n; ++k)
                    b.push_back(c.line[i - 1] + (c.line[i] - c.line[i - 1]) * ((k + 0.5) / n));
            }
            hit.emplace_back(b.size(), 0);
            bins.push_back(std::move(b));
        }
    }
    double covered(size_t t) const {
        return hit[t].empty() ? 1.0 : double(std::count(hit[t].begin(), hit[t].end(), 1)) / double(hit[t].size());
    }
};

/// Cut events against the marked lines; returns when every line reached its coverage. A cut
/// inside a line's radius opens the line within kCutHalfWidth of the hook, and along the way from
/// the previous cut when that one was inside too and at most kCutPassGap away (one pass of the
/// hook); the radius decides inside or outside only.
std::optional<double> judgeCuts(const SessionTimeline& tl, const sim::AssessmentDesc& a, TargetFigures& out) {
    if (a.cuts.empty()) return 0.0;
    CutCoverage cov(a.cuts);
    std::optional<double> met;
    std::vector<std::optional<Vec3>> last(a.cuts.size());
    for (const SessionTimeline::Event& e : tl.events) {
        if (e.kind != "cut") continue;
        if (!finite(e.at)) { // no hook to say where: not on any line
            out.cutOutside += e.count;
            continue;
        }
        bool inside = false;
        for (size_t t = 0; t < a.cuts.size(); ++t) {
            if (lineDistance(e.at, a.cuts[t].line) > a.cuts[t].radius) {
                last[t].reset();
                continue;
            }
            inside = true;
            if (e.swept.size() == 3) { // scissors: the line opens where their blades swept
                for (size_t k = 0; k < cov.bins[t].size(); ++k)
                    if ((sim::closestPointOnTriangle(cov.bins[t][k], e.swept[0], e.swept[1], e.swept[2]).point -
                         cov.bins[t][k])
                            .norm() <= kCutHalfWidth)
                        cov.hit[t][k] = 1;
                last[t].reset();
                continue;
            }
            const Vec3 from = last[t] && (*last[t] - e.at).norm() <= kCutPassGap ? *last[t] : e.at;
            for (size_t k = 0; k < cov.bins[t].size(); ++k)
                if (pointSegment(cov.bins[t][k], from, e.at) <= kCutHalfWidth) cov.hit[t][k] = 1;
            last[t] = e.at;
        }
        if (!inside) out.cutOutside += e.count;
        bool all = true;
        for (size_t t = 0; t < a.cuts.size(); ++t)
            all &= cov.covered(t) >= a.cuts[t].coverage - 1e-12;
        if (all && !met) met = e.t_s;
    }
    out.cutCoverage = 1;
    for (size_t t = 0; t < a.cuts.size(); ++t)
        out.cutCoverage = std::min(out.cutCoverage, cov.covered(t));
    return met;
}

std::optional<double> judgeClips(const SessionTimeline& tl, const sim::AssessmentDesc& a, TargetFigures& out) {
    if (a.clips.empty()) return 0.0;
    std::vector<int> on(a.clips.size(), 0);
    std::vector<std::optional<double>> metAt(a.clips.size());
    for (const SessionTimeline::Event& e : tl.events) {
        if (e.kind != "clip") continue;
        int best = -1;
        double bestD = std::numeric_limits<double>::infinity();
        const Vec3 where = e.rest.value_or(e.at); // the targets were picked on the rest pose
        for (size_t t = 0; t < a.clips.size(); ++t)
            if (const double d = (where - a.clips[t].position).norm(); d <= a.clips[t].tolerance && d < bestD)
                best = int(t), bestD = d;
        if (best < 0) {
            ++out.clipsOff;
            continue;
        }
        ++out.clipsOn;
        if (++on[size_t(best)] >= a.clips[size_t(best)].count && !metAt[size_t(best)]) metAt[size_t(best)] = e.t_s;
    }
    double last = 0;
    for (const auto& m : metAt) {
        if (!m) return std::nullopt;
        last = std::max(last, *m);
    }
    return last;
}

/// One pass of the needle through one wall: two successive punctures (in and out) on one side of
/// the wound's plane, in thread order; their mean and the nearer one's distance from the plane.
/// A lone puncture (the needle went in and not out before crossing) is a pass of its own.
struct WallPass {
    Vec3 mean = Vec3::Zero();
    double nearest = std::numeric_limits<double>::infinity();
    int n = 0;
    bool above = false;
};

std::vector<WallPass> wallPasses(const std::vector<Vec3>& p, const sim::SutureTarget& s) {
    std::vector<WallPass> passes;
    for (const Vec3& x : p) {
        const double d = (x - s.planePoint).dot(s.planeNormal);
        if (passes.empty() || passes.back().above != (d > 0) || passes.back().n == 2)
            passes.push_back({Vec3::Zero(), std::abs(d), 0, d > 0});
        WallPass& w = passes.back();
        w.mean += x, ++w.n, w.nearest = std::min(w.nearest, std::abs(d));
    }
    for (WallPass& w : passes)
        w.mean /= w.n;
    return passes;
}

/// Bites from the puncture points in thread order: a pass through the wall on one side of the
/// wound followed by a pass on the other makes a bite; its depth is the nearest puncture's
/// distance from the plane. A pass that makes no bite (a stitch through one wall only), or a bite
/// out of depth, is missed.
std::optional<double> judgeSuture(const SessionResult& r, const sim::AssessmentDesc& a, TargetFigures& out) {
    if (!a.suture) return 0.0;
    const sim::SutureTarget& s = *a.suture;
    std::vector<Vec3> mids;
    const std::vector<WallPass> passes = wallPasses(r.puncturePoints, s);
    size_t i = 0;
    while (i < passes.size()) {
        if (i + 1 < passes.size() && passes[i].above != passes[i + 1].above) {
            const double depth = std::min(passes[i].nearest, passes[i + 1].nearest);
            if (depth >= s.depthMin && depth <= s.depthMax) {
                ++out.bites;
                mids.push_back(0.5 * (passes[i].mean + passes[i + 1].mean));
            } else
                ++out.bitesMissed;
            i += 2;
            continue;
        }
        ++out.bitesMissed;
        ++i;
    }
    for (size_t k = 1; k < mids.size(); ++k) {
        const double d = (mids[k] - mids[k - 1]).norm();
        out.spacingError = std::max({out.spacingError, s.spacingMin - d, d - s.spacingMax});
    }
    // Spacing within its range, or as far out of it as the case's bite_spacing_error_m limit allows.
    const sim::MetricLevel* spacing = a.level("bite_spacing_error_m");
    const double spacingAllowed = spacing && spacing->limit ? *spacing->limit : 0.0;
    if (out.bites < s.bites || out.spacingError > spacingAllowed + 1e-12 || !r.suture ||
        !(r.suture->finalGap <= s.maxGap))
        return std::nullopt;
    // Met at the first sampled frame after the last puncture with the gap closed.
    double lastPuncture = 0;
    for (const SessionTimeline::Event& e : r.timeline.events)
        if (e.kind == "puncture") lastPuncture = e.t_s;
    for (size_t f = 0; f < r.sutureFrames.size(); ++f) {
        const double t = double(f + 1) * r.frameDt;
        if (t >= lastPuncture && r.sutureFrames[f].maxGap >= 0 && r.sutureFrames[f].maxGap <= s.maxGap) return t;
    }
    return r.simTime;
}

TargetFigures judgeTargets(const SessionResult& r, const sim::AssessmentDesc& a) {
    TargetFigures out;
    const auto cuts = judgeCuts(r.timeline, a, out);
    const auto clips = judgeClips(r.timeline, a, out);
    const auto suture = judgeSuture(r, a, out);
    if (a.hasTargets() && cuts && clips && suture) out.metAt = std::max({*cuts, *clips, *suture});
    return out;
}

double idleTime(const SessionTimeline& tl, const std::vector<double>& span, double until) {
    double idle = 0;
    bool started = false;
    for (size_t i = 1; i < tl.t_s.size() && tl.t_s[i] <= until + 1e-9; ++i) {
        const double dt = tl.t_s[i] - tl.t_s[i - 1];
        if (dt <= 0) continue;
        double fastest = 0;
        for (const auto& t : tl.tools)
            if (i < t.tip.size() && finite(t.tip[i]) && finite(t.tip[i - 1]))
                fastest = std::max(fastest, (t.tip[i] - t.tip[i - 1]).norm() / dt);
        started |= fastest >= kIdleSpeed;
        if (started && fastest < kIdleSpeed) idle += span[i - 1];
    }
    return idle;
}

double jerkRms(const SessionTimeline& tl) {
    double sum = 0;
    size_t n = 0;
    for (const auto& t : tl.tools)
        for (size_t i = 0; i + 3 < t.tip.size() && i + 3 < tl.t_s.size(); ++i) {
            const double h = (tl.t_s[i + 3] - tl.t_s[i]) / 3.0;
            if (!(h > 0)) continue;
            const Vec3 j = (t.tip[i + 3] - 3 * t.tip[i + 2] + 3 * t.tip[i + 1] - t.tip[i]) / (h * h * h);
            const double speed = (t.tip[i + 2] - t.tip[i + 1]).norm() / h;
            if (!j.allFinite() || speed < kIdleSpeed) continue;
            sum += j.squaredNorm();
            ++n;
        }
    return n ? std::sqrt(sum / double(n)) : 0.0;
}

int instrumentCollisions(const SessionTimeline& tl) {
    int hits = 0;
    for (size_t a = 0; a < tl.tools.size(); ++a)
        for (size_t b = a + 1; b < tl.tools.size(); ++b) {
            const auto &ta = tl.tools[a], &tb = tl.tools[b];
            bool was = false;
            for (size_t i = 0; i < ta.tip.size() && i < tb.tip.size(); ++i) {
                const double d = (ta.tip[i] - tb.tip[i]).norm();
                const bool now = std::isfinite(d) && d < ta.radius + tb.radius + kCollisionMargin;
                hits += now && !was;
                was = now;
            }
        }
    return hits;
}

/// A tool in use at sample i: its tip moved more than 1 mm within the half second before or after.
bool inUse(const SessionTimeline& tl, const SessionTimeline::Tool& t, size_t i) {
    size_t a = i, b = i;
    while (a > 0 && tl.t_s[i] - tl.t_s[a - 1] <= 0.5)
        --a;
    while (b + 1 < t.tip.size() && b + 1 < tl.t_s.size() && tl.t_s[b + 1] - tl.t_s[i] <= 0.5)
        ++b;
    for (size_t k = a; k < b; ++k)
        if ((t.tip[k + 1] - t.tip[a]).norm() > 0.001 || (t.tip[k + 1] - t.tip[b]).norm() > 0.001) return true;
    return false;
}

double outOfView(const SessionTimeline& tl, const std::vector<double>& span) {
    if (tl.cameraTip.empty() || tl.cameraFovDeg <= 0) return 0;
    const double half = tl.cameraFovDeg * 0.5 * std::numbers::pi / 180.0;
    double out = 0;
    for (size_t i = 0; i < tl.cameraTip.size() && i < tl.cameraView.size() && i < span.size(); ++i) {
        bool any = false;
        for (const auto& t : tl.tools) {
            if (i >= t.tip.size() || !finite(t.tip[i]) || t.kind == "needle" || !inUse(tl, t, i)) continue;
            const Vec3 d = t.tip[i] - tl.cameraTip[i];
            const double c = d.normalized().dot(tl.cameraView[i]);
            any |= !(d.norm() > 1e-9 && c >= std::cos(half));
        }
        if (any) out += span[i];
    }
    return out;
}

/// Every measurable figure, by catalogue name (absent: does not apply to the case).
std::map<std::string, std::optional<double>> measure(const SessionResult& r,
                                                     const std::optional<sim::AssessmentDesc>& desc,
                                                     std::vector<ToolFigures>& tools,
                                                     std::optional<double>& completion) {
    std::map<std::string, std::optional<double>> v;
    const SessionTimeline& tl = r.timeline;
    const std::vector<double> span = sampleSpans(tl);
    const double threshold = desc ? desc->forceThresholdN : sim::AssessmentDesc{}.forceThresholdN;
    auto thresholdOf = [&](const SessionTimeline::Tool& t) { return t.damageForceN > 0 ? t.damageForceN : threshold; };
    for (const auto& t : tl.tools)
        tools.push_back(toolFigures(t, span, thresholdOf(t)));
    TargetFigures targets;
    if (desc && desc->hasTargets()) {
        targets = judgeTargets(r, *desc);
        completion = targets.metAt;
        v["completion_time_s"] = completion;
    }
    if (!tools.empty()) {
        double path = 0, angular = 0, fmax = 0, over = 0, damage = 0, fsum = 0;
        int fn = 0;
        std::map<std::string, double> byHand;
        bool axes = false;
        for (size_t k = 0; k < tools.size(); ++k) {
            const ToolFigures& f = tools[k];
            path += f.pathM, angular += f.angularRad, fmax = std::max(fmax, f.forceMaxN), damage += f.damageNs;
            if (f.hand == "left" || f.hand == "right") byHand[f.hand] += f.pathM;
            axes |= !tl.tools[k].axis.empty();
            for (double x : tl.tools[k].force_n)
                if (std::isfinite(x) && x > kContactForce) fsum += x, ++fn;
        }
        for (size_t i = 0; i < span.size(); ++i) {
            bool any = false;
            for (const auto& t : tl.tools)
                any |= i < t.force_n.size() && t.force_n[i] > thresholdOf(t);
            if (any) over += span[i];
        }
        v["path_length_m"] = path;
        for (const auto& [hand, p] : byHand)
            v["path_length_" + hand + "_m"] = p;
        if (axes) v["angular_path_rad"] = angular;
        if (desc && desc->referencePathM && path > 0) v["economy_of_motion"] = *desc->referencePathM / path;
        v["jerk_rms_m_s3"] = jerkRms(tl);
        v["idle_time_s"] = idleTime(tl, span, completion.value_or(tl.t_s.empty() ? 0.0 : tl.t_s.back()));
        if (tl.tools.size() >= 2) v["instrument_collisions"] = instrumentCollisions(tl);
        if (!tl.cameraTip.empty()) v["out_of_view_s"] = outOfView(tl, span);
        v["force_mean_n"] = fn ? fsum / fn : 0.0;
        v["force_max_n"] = fmax;
        v["force_over_threshold_s"] = over;
        v["tissue_damage_ns"] = damage;
    }
    if (desc && !desc->cuts.empty()) {
        v["cut_coverage"] = targets.cutCoverage;
        v["cut_outside_edges"] = targets.cutOutside;
    }
    if (desc && !desc->clips.empty()) {
        v["clips_on_target"] = targets.clipsOn;
        v["clips_off_target"] = targets.clipsOff;
    }
    if (desc && desc->suture) {
        v["bites"] = targets.bites;
        v["bites_missed"] = targets.bitesMissed;
        v["bite_spacing_error_m"] = targets.spacingError;
    }
    if (desc && desc->vessel) {
        double injury = 0;
        for (size_t i = 0; i < tl.vesselNear.size() && i < span.size(); ++i)
            injury += tl.vesselNear[i] ? span[i] : 0.0;
        v["vessel_injury_s"] = injury;
    }
    if (r.suture && r.suture->gauge) v["final_gap_m"] = r.suture->finalGap;
    if (r.suture) v["max_thread_tension_n"] = r.suture->maxThreadTension;
    return v;
}

MetricResult judge(const sim::MetricInfo& info, std::optional<double> value, const sim::MetricLevel* level) {
    MetricResult m;
    m.name = info.name;
    m.unit = info.unit;
    m.lowerIsBetter = info.lowerIsBetter;
    m.value = value;
    if (m.value && !std::isfinite(*m.value)) m.value.reset();
    auto good = [&](double v, double edge) { return m.lowerIsBetter ? v <= edge : v >= edge; };
    if (level && level->limit) {
        m.limit = level->limit;
        m.passed = m.value && good(*m.value, *m.limit);
    }
    if (level && level->expert) {
        m.expert = level->expert;
        m.bound =
            m.lowerIsBetter ? level->expert->mean + 2 * level->expert->sd : level->expert->mean - 2 * level->expert->sd;
        m.withinExpert = m.value && good(*m.value, m.bound);
    }
    return m;
}

} // namespace

const MetricResult* Assessment::find(std::string_view name) const {
    for (const MetricResult& m : metrics)
        if (m.name == name) return &m;
    return nullptr;
}

bool Assessment::withinExpertLevel() const {
    bool any = false;
    for (const MetricResult& m : metrics)
        if (m.withinExpert) {
            if (!*m.withinExpert) return false;
            any = true;
        }
    return any;
}

Assessment assessSession(const SessionResult& r, const std::optional<sim::AssessmentDesc>& desc) {
    Assessment a;
    a.judged = desc.has_value();
    const auto values = measure(r, desc, a.tools, a.completionS);
    for (const sim::MetricInfo& info : sim::metricCatalogue()) {
        const auto it = values.find(std::string(info.name));
        const sim::MetricLevel* level = desc ? desc->level(info.name) : nullptr;
        // A metric the case judges but the session could not measure (no laparoscope for
        // out_of_view_s, no suture for final_gap_m) is listed without a value: it fails its limit.
        if (it == values.end() && !level) continue;
        a.metrics.push_back(judge(info, it == values.end() ? std::nullopt : it->second, level));
        a.passed &= a.metrics.back().passed;
    }
    if (!a.judged) a.passed = true;
    return a;
}

std::string Assessment::verdictDetail() const {
    std::string s;
    if (find("completion_time_s")) s = "completion " + formatFigure(completionS) + " s";
    bool levels = false;
    for (const MetricResult& m : metrics)
        levels |= m.expert.has_value();
    if (levels)
        s += (s.empty() ? "" : "; ") +
             std::string(withinExpertLevel() ? "within the expert level" : "not within the expert level");
    return s;
}

std::string formatFigure(std::optional<double> v) {
    if (!v || !std::isfinite(*v)) return "—";
    double x = *v;
    if (x == 0) x = 0; // no "-0"
    char buf[48];
    const double ax = std::abs(x);
    if (ax != 0 && (ax < 1e-3 || ax >= 1e6))
        std::snprintf(buf, sizeof buf, "%.3g", x);
    else if (ax >= 100 || x == std::round(x))
        std::snprintf(buf, sizeof buf, "%.0f", x);
    else
        std::snprintf(buf, sizeof buf, "%.3g", x);
    return buf;
}

std::string metricLine(const MetricResult& m) {
    std::string s = m.name + " " + formatFigure(m.value) + " " + m.unit;
    if (m.limit) s += " (limit " + std::string(m.lowerIsBetter ? "≤ " : "≥ ") + formatFigure(m.limit) + ")";
    s += m.limit ? (m.passed ? " pass" : " FAIL") : "";
    if (m.expert)
        s += std::string(", expert ") + (m.lowerIsBetter ? "≤ " : "≥ ") + formatFigure(m.bound) +
             (*m.withinExpert ? ": within" : ": outside");
    return s;
}

} // namespace viscera::player
