#include "sim/scene/port_reach.hpp"

#include "sim/scene/instrument_track.hpp"
#include "sim/scene/scene.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>

namespace viscera::sim {

namespace {

std::string fixed(double v, int digits) {
    char buf[48];
    std::snprintf(buf, sizeof buf, "%.*f", digits, v);
    return buf;
}

std::string point(const Vec3& p) {
    if (!p.allFinite()) return "a non-finite point";
    return "(" + fixed(p.x(), 3) + ", " + fixed(p.y(), 3) + ", " + fixed(p.z(), 3) + ")";
}

/// The points of a cut line the hook must reach: its vertices and points every kReachSampleM.
std::vector<Vec3> linePoints(const std::vector<Vec3>& line) {
    std::vector<Vec3> out;
    for (size_t i = 0; i < line.size(); ++i) {
        out.push_back(line[i]);
        if (i + 1 == line.size()) break;
        const double len = (line[i + 1] - line[i]).norm();
        const int n = static_cast<int>(std::min(std::floor(len / kReachSampleM), 10000.0));
        for (int k = 1; k < n; ++k)
            out.push_back(line[i] + (line[i + 1] - line[i]) * (double(k) / n));
    }
    return out;
}

} // namespace

std::optional<PortFrame> instrumentPortFrame(const InstrumentDesc& in) {
    if (!in.port.declared || in.trackText.empty()) return std::nullopt;
    try {
        const InstrumentTrack track = InstrumentTrack::parse(in.trackText, in.name);
        if (track.keys().empty()) return std::nullopt;
        return makePortFrame(in.port, track.keys().front().position, in.device.motionScale);
    } catch (const std::exception&) {
        return std::nullopt; // the track's own rule is the reader's to report
    }
}

std::vector<ReachTarget> targetsToReach(const InstrumentDesc& instrument, const AssessmentDesc& a) {
    const InstrumentDesc::Kind kind = instrument.kind;
    std::vector<ReachTarget> out;
    if (kind == InstrumentDesc::Kind::EnergyHook || kind == InstrumentDesc::Kind::Scissors)
        for (size_t c = 0; c < a.cuts.size(); ++c)
            out.push_back({"assessment.targets.cut[" + std::to_string(c) + "]", linePoints(a.cuts[c].line)});
    if (kind == InstrumentDesc::Kind::ClipApplier)
        for (size_t c = 0; c < a.clips.size(); ++c)
            out.push_back({"assessment.targets.clip[" + std::to_string(c) + "]", {a.clips[c].position}});
    return out;
}

std::string reachRule(const PortFrame& port, const Vec3& target, double tolerance) {
    if (!target.allFinite()) return "is not a finite point";
    const PortPose pose = constrainToPort(port, target);
    if ((pose.tip - target).norm() <= tolerance) return {};
    const PortDesc& p = port.desc;
    const Vec3 v = target - p.position;
    const double angle = std::acos(std::clamp(v.normalized().dot(port.axis), -1.0, 1.0)) * 180.0 / M_PI;
    if (angle > p.maxAngleDeg)
        return fixed(angle, 1) + "° from the port's axis, beyond max_angle_deg " + fixed(p.maxAngleDeg, 1);
    return fixed(v.norm(), 3) + " m from the port, outside the insertion range [" + fixed(p.insertionMin, 3) + ", " +
           fixed(p.insertionMax, 3) + "]";
}

std::vector<ReachProblem> unreachableTargets(const SceneDesc& scene, double tolerance) {
    std::vector<ReachProblem> out;
    if (!scene.assessment || !scene.interaction) return out;
    const auto& instruments = scene.interaction->instruments;
    for (size_t i = 0; i < instruments.size(); ++i) {
        const std::optional<PortFrame> frame = instrumentPortFrame(instruments[i]);
        if (!frame) continue;
        for (const ReachTarget& t : targetsToReach(instruments[i], *scene.assessment)) {
            for (const Vec3& p : t.points) {
                const std::string rule = reachRule(*frame, p, tolerance);
                if (rule.empty()) continue;
                const double d = p.allFinite() ? (constrainToPort(*frame, p).tip - p).norm() : INFINITY;
                ReachProblem r{i, t.field, p, d, {}};
                r.message = "interaction.instruments[" + std::to_string(i) + "] '" + instruments[i].name +
                            "': its port cannot reach " + t.field + " at " + point(p) + ": " + rule;
                out.push_back(std::move(r));
                break;
            }
        }
    }
    return out;
}

} // namespace viscera::sim
