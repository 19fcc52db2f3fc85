// Suturing off the critical path [B §2.2.5, §3.1–3.3]: the background refactorization swapped in at
// a fixed solve, pinned and prefetched constrained nodes. A run must be repeatable bit for bit, and
// stay finite with bounded forces when the needle moves far faster than recorded.
#include "sim/suture/anastomosis.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace viscera::sim;

namespace {

SutureSettings backgroundSettings() {
    SutureSettings s;
    s.needle.punctureForce = 0.008;
    s.fem.youngsModulus = 60e3;
    s.fem.refactorMode = RefactorMode::Background;
    s.fem.refactorDisplacement = 0.05; // several refactorizations in a short run
    s.fem.refactorLatencySteps = 5;
    return s;
}

struct Trace {
    std::vector<Vec3> x;
    std::vector<int> refactoredAt, puncturedAt;
    int factorizations = 0, punctures = 0;
    double maxForce = 0;
    bool finite = true;
};

Trace runOnce(const AnastomosisSpec& spec, const SutureSettings& s, size_t every = 1) {
    AnastomosisRun a = makeAnastomosisRun(spec, s);
    Trace t;
    for (size_t f = 0; f < a.frames.size(); f += every) {
        const SutureStepStats st = a.sim->step(a.frames[f]);
        t.finite = t.finite && st.finite && std::isfinite(st.needleForce) && std::isfinite(st.threadTension);
        if (st.refactored) t.refactoredAt.push_back(static_cast<int>(f));
        if (st.punctured) t.puncturedAt.push_back(static_cast<int>(f));
        t.maxForce = std::max({t.maxForce, st.needleForce, st.threadTension});
        t.punctures = st.punctures;
    }
    t.x = a.sim->positions();
    t.factorizations = a.sim->fem().factorizations();
    for (const Vec3& p : t.x)
        t.finite = t.finite && p.allFinite();
    return t;
}

} // namespace

TEST(SutureRealtime, BackgroundRefactorRunsAreBitIdentical) {
    AnastomosisSpec spec;
    spec.stitches = 1;
    spec.pullFrames = 10;
    const SutureSettings s = backgroundSettings();
    const Trace a = runOnce(spec, s), b = runOnce(spec, s);
    ASSERT_TRUE(a.finite && b.finite);
    EXPECT_GE(a.factorizations, 3); // the background factor was swapped in (more than once)
    EXPECT_GE(a.punctures, 4);
    EXPECT_EQ(a.refactoredAt, b.refactoredAt); // at the same steps
    EXPECT_EQ(a.puncturedAt, b.puncturedAt);
    EXPECT_EQ(a.x, b.x); // bit for bit
}

TEST(SutureRealtime, ContactPrefetchChangesNoResult) {
    // It only decides when K⁻¹ columns are computed: the constraints, and so the positions, are the
    // same to the rounding of the column batches.
    AnastomosisSpec spec;
    spec.stitches = 1;
    spec.pullFrames = 30;
    SutureSettings s = backgroundSettings();
    s.fem.refactorMode = RefactorMode::Synchronous;
    s.fem.refactorDisplacement = 0.25;
    const Trace with = runOnce(spec, s);
    s.contactLookaheadSteps = 0;
    s.fem.prefetchNodesPerSolve = 0;
    const Trace without = runOnce(spec, s);
    ASSERT_TRUE(with.finite && without.finite);
    EXPECT_EQ(with.puncturedAt, without.puncturedAt);
    double d = 0;
    for (size_t v = 0; v < with.x.size(); ++v)
        d = std::max(d, (with.x[v] - without.x[v]).norm());
    EXPECT_LT(d, 1e-9); // m
}

TEST(SutureRealtime, FastNeedleWithTheShortestLatencyStaysFiniteAndBounded) {
    // 10× the recorded speed (30° per frame), the worker joined one solve after the request and one
    // carried node per solve: every value finite, the forces within the console's 15 N.
    AnastomosisSpec spec;
    spec.stitches = 2;
    spec.pullFrames = 40;
    SutureSettings s = backgroundSettings();
    s.fem.refactorLatencySteps = 1;
    s.fem.refactorNodesPerSolve = 1;
    s.fem.refactorDisplacement = 0.02;
    const Trace t = runOnce(spec, s, 10);
    ASSERT_TRUE(t.finite);
    EXPECT_GE(t.punctures, 4);
    EXPECT_GE(t.factorizations, 2);
    EXPECT_LT(t.maxForce, 15.0) << "N";
}
