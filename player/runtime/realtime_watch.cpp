#include "runtime/realtime_watch.hpp"

#include <algorithm>
#include <cstdio>

namespace viscera::player {
namespace {

std::string fixed(double v, int decimals) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
    return buf;
}

} // namespace

double RealTimeWatch::meanStepMs(const std::vector<sim::FrameRecord>& frames, size_t begin, size_t end) {
    end = std::min(end, frames.size());
    if (begin >= end) return 0;
    double sum = 0;
    for (size_t f = begin; f < end; ++f)
        sum += frames[f].stepMs;
    return sum / double(end - begin);
}

std::optional<std::string> RealTimeWatch::afterFrame(const std::vector<sim::FrameRecord>& frames) {
    if (frames.size() != kWarmupFrames + kEstimateFrames || !(m_dt > 0)) return std::nullopt;
    const double ms = meanStepMs(frames, kWarmupFrames, frames.size());
    if (!(ms > 0)) return std::nullopt;
    m_estimate = m_dt * 1e3 / ms;
    if (m_estimate >= 1) return std::nullopt;
    return "real time: this machine runs the case at " + fixed(m_estimate, 2) + " of real time (physics " +
           fixed(ms, 1) + " ms per frame against the case's " + fixed(m_dt * 1e3, 1) + " ms, frames " +
           std::to_string(kWarmupFrames + 1) + "-" + std::to_string(frames.size()) +
           "): the picture will trail the hands further and further and the forces go stale, so the session "
           "will not be the authored one";
}

std::string RealTimeWatch::verdict(const std::vector<sim::FrameRecord>& frames, double lagGrowthMs,
                                   int64_t inputMissed) const {
    if (!(m_dt > 0) || frames.size() <= kWarmupFrames) return {};
    const double ms = meanStepMs(frames, kWarmupFrames, frames.size());
    const double frameMs = m_dt * 1e3;
    const bool slow = ms > frameMs;
    const bool late = lagGrowthMs > kMaxLagMs;
    if (!slow && !late && inputMissed == 0) return {};
    std::string e = std::string(slow || late ? "real time: the physics fell behind the wall clock"
                                             : "real time: frames lost their input") +
                    " (mean step " + fixed(ms, 1) + " ms against the " + fixed(frameMs, 1) +
                    " ms frame; after the first " + std::to_string(kWarmupFrames) + " frames they fell up to " +
                    fixed(lagGrowthMs, 0) + " ms further behind, allowed " + fixed(kMaxLagMs, 0) + " ms";
    if (inputMissed > 0) e += "; " + std::to_string(inputMissed) + " frames lost their own input";
    return e + "): the picture trailed the hands and the forces went stale, so this session was not the authored one";
}

std::vector<std::string> RealTimeWatch::windowNotice(bool estimateWarned, int frame, double lagMs, double lagGrowthMs,
                                                     double lagGrowthMaxMs) {
    if (estimateWarned) return {"Not real time on this machine:", "the picture trails your hands"};
    if (frame <= 0) return {};
    char line[96];
    if (lagGrowthMs > kMaxLagMs) {
        std::snprintf(line, sizeof line, "Behind real time by %.1f s:", 1e-3 * lagMs);
        return {line, "the picture trails your hands"};
    }
    if (lagGrowthMaxMs > kMaxLagMs) {
        std::snprintf(line, sizeof line, "Fell behind real time (%.1f s):", 1e-3 * lagGrowthMaxMs);
        return {line, "not the authored session"};
    }
    return {};
}

} // namespace viscera::player
