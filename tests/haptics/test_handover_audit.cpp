// The hand-over audit: servo ticks checked against the physics thread's own publish log. On the
// newest model every tick's age is below the physics step in progress, however long that step
// is; a tick that still uses a model after its successor was published counts and pushes the
// age ratio over 1. (ServoLoop.ContactModelAge… runs it on the servo loop's own trace.)
#include "haptics/handover_audit.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace viscera::haptics;

namespace {

constexpr int64_t kMs = 1'000'000;

/// Publishes at the given completion times (stamp 50 µs before), ticks every 1 ms in between,
/// each tick using `frameAt(t)`.
template <class FrameAt>
HandoverFigures run(const std::vector<int64_t>& done, int64_t until, FrameAt frameAt, double period_s = 1.0 / 60) {
    HandoverAudit audit(period_s);
    size_t next = 0;
    for (int64_t t = 0; t < until; t += kMs) {
        while (next < done.size() && done[next] <= t) {
            audit.published(static_cast<int64_t>(next), done[next] - 50'000, done[next]);
            ++next;
        }
        audit.used(t, frameAt(t, static_cast<int64_t>(next) - 1));
    }
    return audit.figures();
}

std::vector<int64_t> regular(int frames, int64_t step) {
    std::vector<int64_t> d;
    for (int k = 0; k < frames; ++k)
        d.push_back(k * step + 100'000);
    return d;
}

} // namespace

TEST(HandoverAudit, TicksOnTheNewestModelStayWithinTheStepInProgress) {
    const auto done = regular(60, 16'666'667);
    const HandoverFigures f = run(done, 60 * 16'666'667, [](int64_t, int64_t newest) { return newest; });
    EXPECT_EQ(f.ticksOnOlderModel, 0u);
    EXPECT_EQ(f.firstOlderTick_s, -1);
    EXPECT_EQ(f.logErrors, 0u);
    EXPECT_EQ(f.ticksChecked, 1000u); // ticks at 0 … 1000 ms; none before the first publish at 0.1 ms
    EXPECT_EQ(f.modelsPublished, 60);
    EXPECT_GT(f.maxAgeOverStep, 0.9);
    EXPECT_LT(f.maxAgeOverStep, 1.0);
    EXPECT_NEAR(f.stepMean_ms, 16.666667, 1e-6);
    EXPECT_NEAR(f.stepMax_ms, 16.666667, 1e-6);
    EXPECT_EQ(f.stepsOverPeriod, 0);
}

TEST(HandoverAudit, ASlowPhysicsStepIsLongButNotStale) {
    // Step 10 takes 40 ms: the ticks keep the newest model, whose age grows to ~40 ms but stays
    // within the step in progress; the interval counts as one step over the period.
    std::vector<int64_t> done = regular(30, 16'666'667);
    for (size_t k = 11; k < done.size(); ++k)
        done[k] += 40 * kMs - 16'666'667;
    const HandoverFigures f = run(done, done.back() + kMs, [](int64_t, int64_t newest) { return newest; });
    EXPECT_EQ(f.ticksOnOlderModel, 0u);
    EXPECT_LT(f.maxAgeOverStep, 1.0);
    EXPECT_NEAR(f.stepMax_ms, 40.0, 1e-6);
    EXPECT_EQ(f.stepsOverPeriod, 1);
}

TEST(HandoverAudit, AServoThatMissesAPublishIsCaught) {
    // The servo keeps frame 9 for 5 ms after frame 10 was out (a lost or late hand-over).
    const auto done = regular(30, 16'666'667);
    const HandoverFigures f = run(done, 30 * 16'666'667, [&](int64_t t, int64_t newest) {
        return newest == 10 && t < done[10] + 5 * kMs ? int64_t(9) : newest;
    });
    EXPECT_EQ(f.ticksOnOlderModel, 5u);
    // Relative to the first publish (stamped 50 µs before its completion at done[0]).
    EXPECT_GE(f.firstOlderTick_s, 1e-9 * double(done[10] - (done[0] - 50'000)));
    EXPECT_LT(f.firstOlderTick_s, 1e-9 * double(done[10] + kMs - (done[0] - 50'000)));
    EXPECT_GT(f.maxAgeOverStep, 1.0) << "frame 9 outlived the step that replaced it";
}

TEST(HandoverAudit, CountsPublishesOutOfOrderWithoutThrowing) {
    HandoverAudit audit(0.01);
    audit.published(0, 0, 10);
    audit.published(2, 20, 30); // frame 1 skipped
    audit.published(1, 0, 5);   // completes before frame 0 did
    audit.published(1, 20, 30);
    audit.used(100, -1); // no model yet: not counted
    audit.used(200, 5);  // a frame the log never saw published
    const HandoverFigures f = audit.figures();
    EXPECT_EQ(f.logErrors, 3u);
    EXPECT_EQ(f.modelsPublished, 2);
    EXPECT_EQ(f.ticksChecked, 0u);
}
