// The trainee window's 3D-view pacing (RenderPacer): renders from the physics' spare time, never
// while the physics is behind, at least once a second and once at the end.
#include "runtime/render_pacer.hpp"

#include <gtest/gtest.h>

using namespace viscera::player;

namespace {

LiveState state(int frame, double physicsMs, double lagMs) {
    LiveState s;
    s.frame = frame;
    s.time_s = frame / 60.0;
    s.physicsMs = physicsMs;
    s.lagMs = lagMs;
    return s;
}

} // namespace

TEST(RenderPacer, TheGapGrowsAsThePhysicsLeavesLessTime) {
    const double frame = 1000.0 / 60;
    EXPECT_DOUBLE_EQ(RenderPacer::minGapMs(1.0, 5.0, frame), 4.0) << "a GPU render: a quarter of the time at most";
    // llvmpipe's 70 ms render beside the rectum's 12.1 ms physics: spare 0.274 -> gap 7.3 R.
    EXPECT_NEAR(RenderPacer::minGapMs(70.0, 12.1, frame), 70.0 * 2 / (1 - 12.1 / frame), 1e-9);
    EXPECT_DOUBLE_EQ(RenderPacer::minGapMs(70.0, 15.5, frame), RenderPacer::kMaxGapMs) << "capped at a second";
    EXPECT_DOUBLE_EQ(RenderPacer::minGapMs(10.0, 20.0, frame), RenderPacer::kMaxGapMs) << "no spare time";
    EXPECT_DOUBLE_EQ(RenderPacer::minGapMs(10.0, 0.0, 0.0), 40.0) << "physics not measured yet";
}

TEST(RenderPacer, RendersWhenThePhysicsKeptUpAndNeverFreezes) {
    RenderPacer p;
    EXPECT_TRUE(p.due(state(0, 0, 0), false, -1, 0)) << "the first view at once";
    // A slow start leaves every frame 300 ms late: that offset is not "behind".
    for (int f = 6; f < 20; ++f)
        EXPECT_FALSE(p.due(state(f, 5.0, 300.0), false, 10.0, 20.0)) << "within the gap";
    EXPECT_TRUE(p.due(state(20, 5.0, 300.0), false, 80.0, 20.0)) << "gap of 4 R passed, kept up";
    // Fallen behind by more than a frame since: no render until it catches up, or a second passed.
    EXPECT_FALSE(p.due(state(21, 5.0, 340.0), false, 500.0, 20.0));
    EXPECT_TRUE(p.due(state(22, 5.0, 340.0), false, 1000.0, 20.0));
    EXPECT_TRUE(p.due(state(23, 5.0, 305.0), false, 100.0, 20.0)) << "caught up";
    EXPECT_TRUE(p.due(state(24, 30.0, 900.0), true, 1.0, 20.0)) << "the last frame is always shown";
}
