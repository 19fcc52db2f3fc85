#pragma once
/// Whether a real-time session keeps real time, said at load and at the end instead of silently
/// diverging from the authored session: a frame that starts late still takes its own instant's
/// input (HapticRig), but the picture trails the hands by the lag, the servo renders forces from
/// an ever older contact model (zeroed once stale), and past ServoLoop::kPoseHistory ticks the
/// input itself is lost.
///
/// Estimate: after kEstimateFrames frames past the first kWarmupFrames (shader-free, but the
/// first frames fill caches and start the workers), the mean physics step against the frame time
/// step; below real time, a warning once (log, report, the trainee window in red).
/// Verdict at the end: the session fell behind when the mean step over the frames past the
/// warm-up exceeded the frame time step, the frames fell more than kMaxLagMs further behind the
/// wall clock after the warm-up (HapticsResult::lagGrowthMaxMs: a slow start shifts the whole
/// session and is not counted), or frames lost their own input (HapticsResult::inputMissed);
/// then an error (status FAILED, exit 3). A shorter delay that the physics makes up changes no
/// outcome (every frame takes its own instant's input), only how late the picture is then.
#include "sim/scene/world.hpp"

#include <optional>
#include <string>
#include <vector>

namespace viscera::player {

class RealTimeWatch {
public:
    static constexpr size_t kWarmupFrames = 5;
    static constexpr size_t kEstimateFrames = 30;
    /// The largest delay of the picture behind the hands a session may build up and still count
    /// as real time: 200 ms, where delays begin to cost teleoperated task performance.
    static constexpr double kMaxLagMs = 200.0;

    /// frameDt: the case's frame time step, s (> 0).
    explicit RealTimeWatch(double frameDt) : m_dt(frameDt) {}

    /// Call after every frame with all frames so far. Returns the warning once, at the frame where
    /// the estimate is made, when the estimate is below real time.
    std::optional<std::string> afterFrame(const std::vector<sim::FrameRecord>& frames);
    /// Real-time factor estimated from the first frames (0 before the estimate).
    double estimate() const { return m_estimate; }
    /// The error for a session that fell behind (empty when it kept real time). lagGrowthMs: how
    /// much later than at the end of the warm-up a frame started at most, ms; inputMissed: frames
    /// that took the latest input instead of their own instant's.
    std::string verdict(const std::vector<sim::FrameRecord>& frames, double lagGrowthMs, int64_t inputMissed = 0) const;

    /// What the trainee window says in red about real time (none, or two lines), from the live
    /// figures: the load-time estimate's warning; "Behind real time by X s" while the frames run
    /// more than kMaxLagMs later than after the warm-up; once they fell that far behind, also after
    /// they caught up again, that the session was not the authored one (the verdict at the end).
    /// `frame`: frames done; lag figures in ms.
    static std::vector<std::string> windowNotice(bool estimateWarned, int frame, double lagMs, double lagGrowthMs,
                                                 double lagGrowthMaxMs);

private:
    /// Mean step, ms, over frames [begin, end) (0 when empty).
    static double meanStepMs(const std::vector<sim::FrameRecord>& frames, size_t begin, size_t end);
    double m_dt;
    double m_estimate = 0;
};

} // namespace viscera::player
