#include "runtime/timeline.hpp"

#include "sim/scene/world.hpp"

#include <algorithm>
#include <limits>
#include <string_view>

namespace viscera::player {

TimelineRecorder::TimelineRecorder(const sim::World& world, size_t maxSamples)
    : m_maxSamples(std::max<size_t>(maxSamples, 2)) {
    if (const sim::InteractionRuntime* in = world.interaction()) {
        for (size_t i = 0; i < in->instrumentCount(); ++i) {
            const sim::InstrumentDesc& d = in->instrumentDesc(i);
            m_tl.tools.push_back({d.name,
                                  sim::kindName(d.kind),
                                  d.device.hand,
                                  d.radius,
                                  d.device.damageForceN.value_or(0.0),
                                  {},
                                  {},
                                  {}});
        }
        m_grasped.assign(in->instrumentCount(), 0);
        m_cut = in->summary().fasciaEdgesCut + in->summary().fatEdgesCut;
        m_clips = static_cast<int>(in->summary().clips.size());
    }
    for (size_t t = 0; t < world.toolCount(); ++t)
        m_tl.tools.push_back({world.toolDesc(t).name,
                              "probe",
                              world.toolDesc(t).hand,
                              world.toolDesc(t).radius,
                              world.toolDesc(t).damageForceN.value_or(0.0),
                              {},
                              {},
                              {}});
    if (world.sutureReport()) {
        const auto& su = world.scene().suture;
        m_tl.tools.push_back({"needle", "needle", su ? su->device.hand : "any", 0.0, 0.0, {}, {}, {}});
    }
    if (const sim::Laparoscope* scope = world.laparoscope()) m_tl.cameraFovDeg = scope->desc().fovDeg;
    if (const auto& a = world.scene().assessment; a && a->vessel)
        for (size_t b = 0; b < world.bodyCount(); ++b)
            if (world.bodyName(b) == a->vessel->body) {
                m_vesselBody = static_cast<int>(b);
                m_vesselMargin = a->vessel->margin;
            }
}

bool TimelineRecorder::hookNearVessel(const sim::World& world) const {
    const sim::InteractionRuntime* in = world.interaction();
    if (!in) return false;
    const std::vector<sim::Vec3>& x = world.positions(static_cast<size_t>(m_vesselBody));
    for (const sim::InstrumentState& s : in->summary().instruments)
        if (std::string_view(s.kind) == "energy_hook" && s.act)
            for (const sim::Vec3& p : x)
                if ((p - s.tip).squaredNorm() <= m_vesselMargin * m_vesselMargin) return true;
    return false;
}

void TimelineRecorder::sample(const sim::World& world) {
    m_tl.t_s.push_back(world.time());
    size_t k = 0;
    if (const sim::InteractionRuntime* in = world.interaction())
        for (const sim::InstrumentState& s : in->summary().instruments) {
            if (k >= m_tl.tools.size()) break;
            m_tl.tools[k].tip.push_back(s.tip);
            m_tl.tools[k].force_n.push_back(s.force.norm());
            m_tl.tools[k].axis.push_back(s.shaftAxis.normalized());
            ++k;
        }
    for (size_t t = 0; t < world.toolCount() && k < m_tl.tools.size(); ++t, ++k) {
        const sim::ToolContact& c = world.toolContact(t);
        m_tl.tools[k].tip.push_back(c.centre);
        m_tl.tools[k].force_n.push_back(c.force.norm());
        if (const sim::PortDesc& port = world.toolDesc(t).port; port.declared)
            m_tl.tools[k].axis.push_back((c.centre - port.position).norm() > 1e-9
                                             ? Eigen::Vector3d((c.centre - port.position).normalized())
                                             : Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN()));
    }
    if (const sim::SutureReport* su = world.sutureReport(); su && k < m_tl.tools.size()) {
        // The tip: the far end of the curve (the curve is parameterized by length from its end).
        const Eigen::Vector3d tip = su->needleCurve().point(su->needleLength());
        m_tl.tools[k].tip.push_back(tip);
        const std::vector<sim::SutureFrameRecord>& fr = su->frames();
        m_tl.tools[k].force_n.push_back(fr.empty() ? 0.0 : fr.back().needleForce);
        ++k;
    }
    if (m_vesselBody >= 0) m_tl.vesselNear.push_back(hookNearVessel(world) ? 1 : 0);
    if (const sim::Laparoscope* scope = world.laparoscope()) {
        m_tl.cameraTip.push_back(scope->pose().tip);
        m_tl.cameraView.push_back(scope->pose().view);
        m_tl.cameraSteering.push_back(scope->steering() ? 1 : 0);
    }
    // Every tool has one entry per sample (a tool the world no longer reports holds its last).
    for (SessionTimeline::Tool& tool : m_tl.tools)
        while (tool.tip.size() < m_tl.t_s.size()) {
            tool.tip.push_back(Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN())); // a gap
            tool.force_n.push_back(std::numeric_limits<double>::quiet_NaN());
        }
}

void TimelineRecorder::record(const sim::World& world) {
    const double t = world.time();
    const int frame = world.frameCount();
    if (const sim::InteractionRuntime* in = world.interaction()) {
        const sim::InteractionSummary& s = in->summary();
        for (size_t i = 0; i < s.instruments.size() && i < m_grasped.size(); ++i) {
            const int g = s.instruments[i].grasped;
            const Eigen::Vector3d& tip = s.instruments[i].tip;
            if (g > 0 && m_grasped[i] == 0) m_tl.events.push_back({t, frame, "grasp", s.instruments[i].name, g, tip});
            if (g == 0 && m_grasped[i] > 0) m_tl.events.push_back({t, frame, "release", s.instruments[i].name, 1, tip});
            m_grasped[i] = g;
        }
        const int cut = s.fasciaEdgesCut + s.fatEdgesCut;
        if (cut > m_cut) {
            // The energized hook or the scissors that closed, else the first cutter; where the
            // tissue was cut (the cut edges' mean) when the cutter says, else its tip.
            std::string by;
            Eigen::Vector3d at = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN()); // no cutter
            std::vector<Eigen::Vector3d> swept;
            for (const sim::InstrumentState& st : s.instruments)
                if ((std::string_view(st.kind) == "energy_hook" || std::string_view(st.kind) == "scissors") &&
                    (by.empty() || st.act || st.cutAt)) {
                    by = st.name;
                    at = st.cutAt.value_or(st.tip);
                    swept.clear();
                    if (st.swept) swept.assign(st.swept->begin(), st.swept->end());
                }
            m_tl.events.push_back({t, frame, "cut", by, cut - m_cut, at, std::move(swept)});
        }
        m_cut = cut;
        for (size_t c = static_cast<size_t>(m_clips); c < s.clips.size(); ++c)
            m_tl.events.push_back({s.clips[c].firedAt,
                                   frame,
                                   "clip",
                                   s.clips[c].instrument,
                                   1,
                                   s.clips[c].centre,
                                   {},
                                   s.clips[c].restCentre});
        m_clips = static_cast<int>(s.clips.size());
    }
    if (const sim::SutureReport* su = world.sutureReport(); su && !su->frames().empty()) {
        const int p = su->frames().back().punctures;
        if (p > m_punctures)
            m_tl.events.push_back(
                {t, frame, "puncture", "needle", p - m_punctures, su->needleCurve().point(su->needleLength())});
        m_punctures = p;
    }
    if (m_frames++ % m_tl.stride == 0) sample(world);
    if (m_tl.t_s.size() > m_maxSamples) { // keep every other sample, double the stride
        auto halve = [](auto& v) {
            size_t w = 0;
            for (size_t r = 0; r < v.size(); r += 2)
                v[w++] = v[r];
            v.resize(w);
        };
        halve(m_tl.t_s);
        halve(m_tl.cameraTip);
        halve(m_tl.cameraView);
        halve(m_tl.cameraSteering);
        halve(m_tl.vesselNear);
        for (SessionTimeline::Tool& tool : m_tl.tools) {
            halve(tool.tip);
            halve(tool.force_n);
            halve(tool.axis);
        }
        m_tl.stride *= 2;
    }
}

} // namespace viscera::player
