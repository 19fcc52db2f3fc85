#pragma once
/// Whether a real-time session keeps real time, said at load and at the end instead of silently
/// diverging from the authored session (a device replayed on the wall clock is sampled later and
/// later in simulated time when the physics falls behind).
///
/// Estimate: after kEstimateFrames frames past the first kWarmupFrames (shader-free, but the
/// first frames fill caches and start the workers), the mean physics step against the frame time
/// step; below real time, a warning once (log, report, the trainee window in red).
/// Verdict at the end: the session fell behind when the mean step over the frames past the
/// warm-up exceeded the frame time step or the frames fell more than kMaxLagFrames frame times
/// further behind the wall clock after the warm-up (HapticsResult::lagGrowthMaxMs: a slow start
/// shifts the whole session and is not counted); then an error (status FAILED, exit 3).
#include "sim/scene/world.hpp"

#include <optional>
#include <string>
#include <vector>

namespace viscera::player {

class RealTimeWatch {
public:
    static constexpr size_t kWarmupFrames = 5;
    static constexpr size_t kEstimateFrames = 30;
    static constexpr double kMaxLagFrames = 4.0;

    /// frameDt: the case's frame time step, s (> 0).
    explicit RealTimeWatch(double frameDt) : m_dt(frameDt) {}

    /// Call after every frame with all frames so far. Returns the warning once, at the frame where
    /// the estimate is made, when the estimate is below real time.
    std::optional<std::string> afterFrame(const std::vector<sim::FrameRecord>& frames);
    /// Real-time factor estimated from the first frames (0 before the estimate).
    double estimate() const { return m_estimate; }
    /// The error for a session that fell behind (empty when it kept real time). lagGrowthMs: how
    /// much later than at the end of the warm-up a frame started at most, ms.
    std::string verdict(const std::vector<sim::FrameRecord>& frames, double lagGrowthMs) const;

private:
    /// Mean step, ms, over frames [begin, end) (0 when empty).
    static double meanStepMs(const std::vector<sim::FrameRecord>& frames, size_t begin, size_t end);
    double m_dt;
    double m_estimate = 0;
};

} // namespace viscera::player
