// RealTimeWatch: the estimate from the first frames and the verdict at the end of a paced session.
#include "runtime/realtime_watch.hpp"

#include <gtest/gtest.h>

using viscera::player::RealTimeWatch;
using viscera::sim::FrameRecord;

namespace {

std::vector<FrameRecord> steps(size_t n, double ms) {
    std::vector<FrameRecord> f(n);
    for (size_t i = 0; i < n; ++i) {
        f[i].index = static_cast<int>(i);
        f[i].stepMs = ms;
    }
    return f;
}

/// Feeds frames one by one as the session does; returns the warnings given.
std::vector<std::string> feed(RealTimeWatch& w, const std::vector<FrameRecord>& all) {
    std::vector<std::string> warnings;
    std::vector<FrameRecord> so;
    for (const FrameRecord& f : all) {
        so.push_back(f);
        if (auto m = w.afterFrame(so)) warnings.push_back(*m);
    }
    return warnings;
}

} // namespace

// A case at 10 ms per 16.7 ms frame keeps real time: no warning, no error, estimate 1.67.
TEST(RealTimeWatch, AFastCaseGetsNoWarningAndNoError) {
    RealTimeWatch w(1.0 / 60);
    EXPECT_TRUE(feed(w, steps(100, 10.0)).empty());
    EXPECT_NEAR(w.estimate(), 1.0 / 60 * 1e3 / 10.0, 1e-12);
    EXPECT_EQ(w.verdict(steps(100, 10.0), 5.0), "");
}

// A slow case is said once, at frame 35 (warm-up frames left out), with the figures, and fails.
TEST(RealTimeWatch, ASlowCaseIsSaidOnceAtTheEstimateAndFails) {
    std::vector<FrameRecord> frames = steps(100, 25.0);
    frames[0].stepMs = frames[1].stepMs = 400; // warm-up: not counted
    RealTimeWatch w(1.0 / 60);
    const std::vector<std::string> warnings = feed(w, frames);
    ASSERT_EQ(warnings.size(), 1u);
    EXPECT_NE(warnings[0].find("0.67 of real time"), std::string::npos) << warnings[0];
    EXPECT_NE(warnings[0].find("physics 25.0 ms per frame against the case's 16.7 ms, frames 6-35"), std::string::npos)
        << warnings[0];
    const std::string e = w.verdict(frames, 800);
    EXPECT_NE(e.find("mean step 25.0 ms against the 16.7 ms frame; after the first 5 frames they fell up to 800 ms "
                     "further behind, allowed 200 ms"),
              std::string::npos)
        << e;
}

// A fast mean with a long stall (frames more than 200 ms further behind after the warm-up) fails
// too, and so does a session whose frames lost their input; a delay the physics made up does not;
// fewer frames than the warm-up give no verdict.
TEST(RealTimeWatch, LongStallsFailShortSpikesDoNot) {
    RealTimeWatch w(1.0 / 60);
    const auto frames = steps(100, 12.0);
    EXPECT_NE(w.verdict(frames, 210.0), "");
    EXPECT_EQ(w.verdict(frames, 190.0), "");
    EXPECT_EQ(w.verdict(frames, 20.0), "");
    const std::string lost = w.verdict(frames, 20.0, 3);
    EXPECT_NE(lost.find("3 frames lost their own input"), std::string::npos) << lost;
    EXPECT_EQ(w.verdict(steps(3, 100.0), 500.0), "");
    RealTimeWatch bad(0);
    EXPECT_FALSE(bad.afterFrame(steps(35, 50.0)).has_value());
    EXPECT_EQ(bad.verdict(steps(100, 50.0), 900), "");
}

TEST(RealTimeWatch, TheWindowSaysWhenTheSessionFellBehindEvenAfterItCaughtUp) {
    using W = RealTimeWatch;
    EXPECT_TRUE(W::windowNotice(false, 0, 0, 0, 0).empty()) << "nothing before the first frame";
    EXPECT_TRUE(W::windowNotice(false, 100, 40, 30, 150).empty()) << "within the 200 ms allowance";
    const auto est = W::windowNotice(true, 40, 0, 0, 0);
    ASSERT_EQ(est.size(), 2u);
    EXPECT_EQ(est[0], "Not real time on this machine:");
    const auto now = W::windowNotice(false, 300, 450, 400, 400);
    ASSERT_EQ(now.size(), 2u);
    EXPECT_EQ(now[0], "Behind real time by 0.5 s:") << "the lag now";
    // caught up again, but the end verdict fails on the largest growth: the window says so too
    const auto after = W::windowNotice(false, 600, 20, 10, 298);
    ASSERT_EQ(after.size(), 2u);
    EXPECT_EQ(after[0], "Fell behind real time (0.3 s):");
    EXPECT_EQ(after[1], "not the authored session");
    // the verdict's rule, the same limit
    EXPECT_TRUE(W::windowNotice(false, 600, 0, 0, W::kMaxLagMs).empty());
}
