#include "runtime/report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace viscera::player {

StepTimeStats stepTimeStats(const std::vector<sim::FrameRecord>& frames) {
    StepTimeStats s;
    if (frames.empty()) return s;
    std::vector<double> t;
    t.reserve(frames.size());
    for (const auto& f : frames) t.push_back(f.stepMs);
    std::sort(t.begin(), t.end());
    double sum = 0;
    for (double x : t) sum += x;
    s.mean = sum / static_cast<double>(t.size());
    auto pct = [&](double p) {
        size_t i = static_cast<size_t>(std::ceil(p * static_cast<double>(t.size()))) - 1;
        return t[std::min(i, t.size() - 1)];
    };
    s.p50 = pct(0.50);
    s.p99 = pct(0.99);
    s.max = t.back();
    return s;
}

nlohmann::json reportJson(const SessionResult& r) {
    using nlohmann::json;
    json doc;
    doc["case"] = {{"id", r.caseId}, {"version", r.caseVersion}, {"title", r.title}};
    doc["active_subsystems"] = r.activeSubsystems;
    json frames = json::array();
    for (const auto& f : r.frames)
        frames.push_back({{"index", f.index},
                          {"step_ms", f.stepMs},
                          {"substeps", f.substeps},
                          {"iterations", f.iterations},
                          {"energy_j", f.energy},
                          {"max_displacement_m", f.maxDisplacement}});
    doc["frames"] = std::move(frames);
    json accuracy = json::array();
    for (const auto& a : r.accuracy)
        accuracy.push_back({{"frame", a.frame},
                            {"solver", a.solver},
                            {"iterations", a.iterations},
                            {"rel_error", a.relError},
                            {"time_ms", a.timeMs}});
    doc["accuracy"] = std::move(accuracy);
    doc["invariants"] = {{"all_finite", r.invariants.allFinite},
                         {"max_energy", r.invariants.maxEnergy},
                         {"max_step_displacement_m", r.invariants.maxStepDisplacement},
                         {"max_force_n", r.invariants.maxForce},
                         {"speed_clamps", r.invariants.speedClamps}};
    const StepTimeStats st = stepTimeStats(r.frames);
    doc["metrics"] = {{"frames", r.frames.size()},
                      {"sim_time_s", r.simTime},
                      {"wall_time_s", r.wallTime},
                      {"step_ms_mean", st.mean},
                      {"step_ms_p50", st.p50},
                      {"step_ms_p99", st.p99},
                      {"step_ms_max", st.max},
                      {"nodes", r.nodes},
                      {"tets", r.tets},
                      {"max_node_displacement_m", r.maxNodeDisplacement}};
    doc["errors"] = r.errors;
    return doc;
}

std::string summaryText(const SessionResult& r) {
    const StepTimeStats st = stepTimeStats(r.frames);
    std::string subs;
    for (const auto& s : r.activeSubsystems) subs += (subs.empty() ? "" : ", ") + s;
    char buf[1024];
    std::snprintf(buf, sizeof buf,
                  "case          %s %s%s%s\n"
                  "subsystems    %s\n"
                  "mesh          %zu nodes, %zu tets\n"
                  "frames        %zu (%.3f s simulated in %.3f s wall)\n"
                  "step time     mean %.3f ms, p50 %.3f ms, p99 %.3f ms, max %.3f ms\n"
                  "displacement  max node %.3f mm from rest; max per frame %.3f mm\n"
                  "invariants    all finite: %s, max energy %.4g J, max device force %.3g N\n"
                  "status        %s\n",
                  r.caseId.c_str(), r.caseVersion.c_str(), r.title.empty() ? "" : " — ", r.title.c_str(),
                  subs.empty() ? "(none)" : subs.c_str(), r.nodes, r.tets, r.frames.size(), r.simTime,
                  r.wallTime, st.mean, st.p50, st.p99, st.max, r.maxNodeDisplacement * 1e3,
                  r.invariants.maxStepDisplacement * 1e3, r.invariants.allFinite ? "yes" : "NO",
                  r.invariants.maxEnergy, r.invariants.maxForce,
                  r.ok() ? "ok" : ("FAILED: " + (r.errors.empty() ? std::string("invariants") : r.errors.front())).c_str());
    std::string out = buf;
    // Error against run time on the last sampled frame [A eq. 4.45].
    for (auto it = r.accuracy.rbegin(); it != r.accuracy.rend(); ++it) {
        if (it->solver != "xpbd" || it->relError.size() < 2) continue;
        size_t k = 1;
        while (k < it->relError.size() && it->relError[k] > 1e-4) ++k;
        char line[256];
        if (k < it->relError.size())
            std::snprintf(line, sizeof line, "accuracy      frame %d: XPBD rel. error %.2e after 1 iteration, <= 1e-4 after %d (%.3f ms)\n",
                          it->frame, it->relError[1], it->iterations[k], it->timeMs[k]);
        else
            std::snprintf(line, sizeof line, "accuracy      frame %d: XPBD rel. error %.2e after 1 iteration, %.2e after %d (%.3f ms)\n",
                          it->frame, it->relError[1], it->relError.back(), it->iterations.back(), it->timeMs.back());
        out += line;
        break;
    }
    return out;
}

} // namespace viscera::player
