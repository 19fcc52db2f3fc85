#pragma once
/// Checks the physics → servo hand-over from outside the servo loop: "the age of the contact
/// model at each tick is never more than one physics step".
///
/// The physics thread records, for every contact model it publishes, the model's time stamp and
/// the time the write into the SeqLock had completed (a clock read after the write). Each servo
/// tick reports the time it started and the frame of the model it used (TraceSample). A tick
/// that started after frame f + 1 was completely published, yet used frame f or older, ran on a
/// stale model: the hand-over lost a publish. Otherwise the tick's age is shorter than the
/// physics step then in progress, i.e. the interval from the model's time stamp to the
/// completion of its successor's publish; maxAgeOverStep() is the largest such ratio (< 1 unless
/// a tick was stale; ticks on the newest model, whose successor is not out yet, are checked once
/// it is).
///
/// Nothing here throws: a publish out of order, or a tick on a frame the log never saw, is
/// counted (logErrors) and left out, so the audit cannot take down the physics thread.
///
/// The publish-to-publish interval is the physics step as the servo sees it (step + pacing); its
/// distribution says how far the physics kept to its nominal period. Not thread-safe: the physics
/// thread calls everything (published() after each publish, used() while draining the trace).
#include <cstddef>
#include <cstdint>
#include <vector>

namespace viscera::haptics {

struct HandoverFigures {
    uint64_t ticksChecked = 0;      ///< ticks with a model
    uint64_t ticksOnOlderModel = 0; ///< ticks that used a model older than the newest published
    double firstOlderTick_s = -1;   ///< time of the first such tick after the first publish (-1: none)
    uint64_t logErrors =
        0; ///< publishes out of order or back in time, ticks on a frame never logged (internal errors; ignored)
    double maxAgeOverStep = 0; ///< max over ticks of age / (physics step in progress)
    int64_t modelsPublished = 0;
    // publish-to-publish intervals (ms)
    double stepMean_ms = 0, stepP99_ms = 0, stepMax_ms = 0;
    int64_t stepsOverPeriod = 0; ///< intervals longer than the nominal period by more than one servo tick (1 ms)
};

class HandoverAudit {
public:
    static constexpr int64_t kOverPeriodSlack_ns = 1'000'000; ///< one servo tick

    explicit HandoverAudit(double nominalPeriod_s = 0) : m_period_s(nominalPeriod_s) {}
    void reserve(size_t frames);
    /// Frame `frame` (0, 1, 2, … in order) stamped `stamp_ns`, its write complete at `done_ns`.
    void published(int64_t frame, int64_t stamp_ns, int64_t done_ns);
    /// A servo tick that started at `t_ns` and used frame `frame` (< 0: no model yet; ignored).
    void used(int64_t t_ns, int64_t frame);
    HandoverFigures figures() const;

private:
    double m_period_s;
    std::vector<int64_t> m_stamp, m_done; ///< per frame
    std::vector<int64_t> m_lastUse;       ///< per frame: latest tick start that used it (-1: none)
    uint64_t m_checked = 0, m_older = 0, m_logErrors = 0;
    int64_t m_firstOlder = -1;
};

} // namespace viscera::haptics
