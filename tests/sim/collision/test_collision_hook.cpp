// Collision constraints inside the XPBD iteration [A §5.2.5]: the solver's iteration hook
// (XpbdSolver::setIterationHook) and sim::makeCollisionHook.
#include "sim/collision/collision_solver.hpp"
#include "sim/collision/distance.hpp"
#include "sim/mesh/generators.hpp"
#include "sim/scene/tool_probe.hpp"
#include "sim/xpbd/xpbd_solver.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

using namespace viscera::sim;

namespace {

constexpr double kFrame = 1.0 / 60.0;

struct Slab {
    std::unique_ptr<TetMesh> mesh;
    std::vector<int32_t> fixed;
    std::vector<double> invMass;
    Material material;
};

Slab slab(const Vec3& size, const std::array<int, 3>& cells) {
    Slab s;
    s.mesh = makeBoxTetMesh({Vec3::Zero(), size, cells});
    s.mesh->requireLevel(3);
    for (int32_t v = 0; v < static_cast<int32_t>(s.mesh->vertexCount()); ++v)
        if (s.mesh->positions()[v].z() < 1e-9) s.fixed.push_back(v);
    s.material.youngsModulus = 10000;
    s.material.poissonRatio = 0.3;
    const auto m = lumpedMasses(*s.mesh, s.material.density, s.fixed);
    s.invMass.resize(m.size());
    for (size_t i = 0; i < m.size(); ++i)
        s.invMass[i] = m[i] > 0 ? 1 / m[i] : 0;
    return s;
}

XpbdSettings settings(int substeps, int iterations, int threads) {
    XpbdSettings s;
    s.dt = kFrame;
    s.substeps = substeps;
    s.iterations = iterations;
    s.threads = threads;
    return s;
}

bool identical(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
    if (a.size() != b.size()) return false;
    for (size_t i = 0; i < a.size(); ++i)
        if (a[i] != b[i]) return false;
    return true;
}

ToolShape::Pose translation(const Vec3& t) {
    ToolShape::Pose p = ToolShape::Pose::Identity();
    p.translation() = t;
    return p;
}

} // namespace

// Without a hook, with a hook that does nothing, and with a hook that was set and removed, the
// frames are bit-identical (serial and with two threads); the hook is called once per sweep with
// the substep, iteration and substep length in order.
TEST(XpbdIterationHook, NoOpHookIsBitIdenticalAndCalledAfterEverySweep) {
    const Slab s = slab(Vec3(0.04, 0.04, 0.02), {8, 8, 4});
    for (int threads : {1, 2}) {
        const XpbdSettings xs = settings(4, 3, threads);
        auto plain = XpbdSolver::create(*s.mesh, s.material, s.fixed, xs);
        auto hooked = XpbdSolver::create(*s.mesh, s.material, s.fixed, xs);
        auto removed = XpbdSolver::create(*s.mesh, s.material, s.fixed, xs);
        std::vector<XpbdIterationInfo> calls;
        size_t particles = 0;
        hooked->setIterationHook([&](XpbdParticles& p, const XpbdIterationInfo& info) {
            calls.push_back(info);
            particles = p.size();
        });
        removed->setIterationHook([](XpbdParticles&, const XpbdIterationInfo&) {});
        removed->setIterationHook({});
        for (int f = 0; f < 5; ++f) {
            ASSERT_TRUE(plain->step().finite);
            ASSERT_TRUE(hooked->step().finite);
            ASSERT_TRUE(removed->step().finite);
            ASSERT_TRUE(identical(plain->positions(), hooked->positions())) << "frame " << f;
            ASSERT_TRUE(identical(plain->velocities(), hooked->velocities())) << "frame " << f;
            ASSERT_TRUE(identical(plain->positions(), removed->positions())) << "frame " << f;
        }
        EXPECT_NE(plain->positions()[0 + s.mesh->vertexCount() - 1],
                  s.mesh->positions()[s.mesh->vertexCount() - 1]); // it did move (gravity)
        EXPECT_EQ(particles, s.mesh->vertexCount());
        // Per substep: 3 sweeps, then the velocity pass (iteration 3).
        ASSERT_EQ(calls.size(), 5u * 4u * 4u);
        for (size_t c = 0; c < calls.size(); ++c) {
            EXPECT_EQ(calls[c].substep, static_cast<int>((c / 4) % 4));
            EXPECT_EQ(calls[c].iteration, static_cast<int>(c % 4));
            EXPECT_EQ(calls[c].velocityPass, c % 4 == 3);
            EXPECT_EQ(calls[c].substeps, 4);
            EXPECT_EQ(calls[c].iterations, 3);
            EXPECT_DOUBLE_EQ(calls[c].h, kFrame / 4);
        }
    }
}

// The hook sees the current iterate and its moves stick: a hook that pins one free node to a
// point holds it there at the end of every frame, and the velocity update sees the move.
TEST(XpbdIterationHook, MovesMadeByTheHookAreKept) {
    const Slab s = slab(Vec3(0.04, 0.04, 0.02), {4, 4, 2});
    auto solver = XpbdSolver::create(*s.mesh, s.material, s.fixed, settings(5, 2, 1));
    const size_t node = s.mesh->vertexCount() - 1; // top corner, free
    ASSERT_GT(s.invMass[node], 0);
    const Vec3 target = s.mesh->positions()[node] + Vec3(0, 0, 0.003);
    solver->setIterationHook([&](XpbdParticles& p, const XpbdIterationInfo&) {
        ASSERT_GT(p.inverseMass(node), 0);
        p.setPosition(node, target);
    });
    for (int f = 0; f < 3; ++f) {
        ASSERT_TRUE(solver->step().finite);
        EXPECT_EQ(solver->positions()[node], target);
        // Last substep starts at the target and ends there: velocity (damped) is zero.
        EXPECT_LT(solver->velocities()[node].norm(), 1e-12);
    }
}

// A hook that throws marks the frame non-finite and the frame is rolled back.
TEST(XpbdIterationHook, ThrowingHookRollsTheFrameBack) {
    const Slab s = slab(Vec3(0.04, 0.04, 0.02), {8, 8, 4});
    for (int threads : {1, 2}) {
        auto solver = XpbdSolver::create(*s.mesh, s.material, s.fixed, settings(4, 2, threads));
        ASSERT_TRUE(solver->step().finite);
        const std::vector<Vec3> x = solver->positions(), v = solver->velocities();
        solver->setIterationHook([](XpbdParticles&, const XpbdIterationInfo& info) {
            if (info.substep == 2) throw std::runtime_error("boom");
        });
        EXPECT_FALSE(solver->step().finite);
        EXPECT_TRUE(identical(solver->positions(), x));
        EXPECT_TRUE(identical(solver->velocities(), v));
    }
}

// CollisionSolver on a particle view: offset indexing, fixed particles (inverse mass 0 in the
// view) never move, a view too small is an empty step.
TEST(CollisionHook, ParticleViewOffsetFixedAndSize) {
    CollisionSurfaceDesc d;
    const double L = 0.01;
    d.restPositions = {Vec3(0, 0, 0), Vec3(L, 0, 0), Vec3(L, L, 0), Vec3(0, L, 0)};
    d.triangles = {{0, 1, 2}, {0, 2, 3}};
    d.inverseMass = {1, 1, 1, 1};
    CollisionSettings cs;
    cs.method = CollisionMethod::Polygon;
    cs.maxCorrectionPerStep = 1;
    auto col = CollisionSolver::create(d, cs);
    ToolShape tool = ToolShape::sphere(0.004);
    tool.setPose(translation(Vec3(0.5 * L, 0.5 * L, 0.002))); // 2 mm above the square's centre
    // 2 unrelated particles, then the 4 surface vertices; vertex 2 (particle 4) fixed.
    std::vector<double> xw = {9, 9, 9, 1, 8, 8, 8, 1};
    for (size_t v = 0; v < 4; ++v)
        xw.insert(xw.end(),
                  {d.restPositions[v].x(), d.restPositions[v].y(), d.restPositions[v].z(), v == 2 ? 0.0 : 1.0});
    XpbdParticles view(xw.data(), nullptr, 6);
    col->beginStep(view, 2, tool, 1e-3);
    EXPECT_EQ(col->stats().candidates, 2);
    int contacts = 0;
    for (int k = 0; k < 20; ++k)
        contacts += col->iterate(view, 2, tool);
    EXPECT_GT(contacts, 0);
    EXPECT_EQ(view.position(0), Vec3(9, 9, 9));
    EXPECT_EQ(view.position(1), Vec3(8, 8, 8));
    EXPECT_EQ(view.position(4), d.restPositions[2]); // fixed in the view
    // The others were pushed down, away from the sphere (polygon: below the reach r + margin).
    for (size_t p : {2u, 3u, 5u})
        EXPECT_LT(view.position(p).z(), -1e-4) << "particle " << p;
    // Too small a view: nothing happens.
    const std::vector<double> before = xw;
    XpbdParticles small(xw.data(), nullptr, 5);
    col->beginStep(small, 2, tool, 1e-3);
    EXPECT_EQ(col->stats().candidates, 0);
    EXPECT_EQ(col->iterate(small, 2, tool), 0);
    EXPECT_EQ(xw, before);
}

namespace {

struct SphereRun {
    std::vector<std::vector<Vec3>> frames;
    std::vector<int32_t> contacts; ///< contact vertices of the last frame
    bool finite = true;
};

/// A sphere of radius 8 mm pressed 3 mm into a 4 × 4 × 1.2 cm slab and held (set once, from the
/// first frame: the tissue is pushed out over the first substeps), collision in the iteration.
SphereRun restingSphere(const Slab& s, CollisionMethod method, int threads, int frames, Vec3* centre) {
    const double r = 0.008;
    auto solver = XpbdSolver::create(*s.mesh, s.material, s.fixed, settings(20, 3, threads));
    CollisionSettings cs;
    cs.method = method;
    auto col = CollisionSolver::create(CollisionSurfaceDesc::fromTetMesh(*s.mesh, s.invMass), cs);
    ToolShape tool = ToolShape::sphere(r);
    *centre = Vec3(0.02, 0.02, 0.012 + r - 0.003);
    tool.setPose(translation(*centre));
    solver->setIterationHook(makeCollisionHook(*col, tool));
    SphereRun run;
    for (int f = 0; f < frames; ++f) {
        run.finite = run.finite && solver->step().finite;
        run.frames.push_back(solver->positions());
    }
    run.contacts = col->contactVertices();
    return run;
}

} // namespace

// A resting sphere pressed into a slab: with the contacts solved inside the iteration the slab
// settles (the per-frame motion decays by orders of magnitude and ends below 1 µm), the
// contact vertices end at the tool surface (not inside it, not far from it), and repeat runs
// and thread counts give bit-identical frames.
TEST(CollisionHook, RestingSphereOnSlabConvergesAndIsDeterministic) {
    const Slab s = slab(Vec3(0.04, 0.04, 0.012), {10, 10, 4});
    for (CollisionMethod method :
         {CollisionMethod::Circumsphere, CollisionMethod::BoundingSphere, CollisionMethod::Polygon}) {
        SCOPED_TRACE(toString(method));
        Vec3 c;
        const SphereRun a = restingSphere(s, method, 1, 90, &c);
        ASSERT_TRUE(a.finite);
        auto motion = [&](int f) {
            double m = 0;
            for (size_t v = 0; v < a.frames[f].size(); ++v)
                m = std::max(m, (a.frames[f][v] - a.frames[f - 1][v]).norm());
            return m;
        };
        const double early = motion(5), late = motion(89);
        EXPECT_GT(early, 1e-5);
        EXPECT_LT(late, 1e-6);
        EXPECT_LT(late, 1e-2 * early);
        ASSERT_FALSE(a.contacts.empty());
        double mean = 0, closest = 1;
        for (int32_t v : a.contacts) {
            const double d = (a.frames.back()[v] - c).norm();
            mean += d;
            closest = std::min(closest, d);
        }
        mean /= a.contacts.size();
        // Contact vertices on or just outside the sphere (r = 8 mm): the polygon method keeps
        // them at r + 1 mm margin, the sphere methods at the sphere surface or beyond it.
        EXPECT_GT(closest, 0.008 - 2e-4);
        EXPECT_GT(mean, 0.008);
        EXPECT_LT(mean, 0.008 * 1.5);
        // Every node outside the tool (no tunnelling of a resting contact).
        for (const Vec3& x : a.frames.back())
            EXPECT_GT((x - c).norm(), 0.008 - 2e-4);
        // Repeat run and two threads: bit-identical frames.
        Vec3 c2;
        const SphereRun b = restingSphere(s, method, 1, 30, &c2);
        const SphereRun t = restingSphere(s, method, 2, 30, &c2);
        for (int f = 0; f < 30; ++f) {
            ASSERT_TRUE(identical(a.frames[f], b.frames[f])) << "frame " << f;
            ASSERT_TRUE(identical(a.frames[f], t.frames[f])) << "frame " << f;
        }
    }
}

namespace {

struct SweepRun {
    std::vector<std::vector<Vec3>> frames;
    long tested = 0;   ///< triangles the broad phases looked at, all substeps
    int listsMade = 0; ///< steps that made the reach list anew
    long contacts = 0;
};

/// A 3 mm sphere pressed 1 mm into a 6 × 4 × 1.2 cm slab and dragged across it (and once lifted
/// off and put down again), collision in the iteration, with the given reach-list margin.
SweepRun sweepingSphere(const Slab& s, CollisionMethod method, double margin, int frames) {
    auto solver = XpbdSolver::create(*s.mesh, s.material, s.fixed, settings(20, 3, 1));
    CollisionSettings cs;
    cs.method = method;
    cs.reachListMargin = margin;
    auto col = CollisionSolver::create(CollisionSurfaceDesc::fromTetMesh(*s.mesh, s.invMass), cs);
    const double r = 0.003;
    ToolShape tool = ToolShape::sphere(r);
    SweepRun run;
    auto inner = makeCollisionHook(*col, tool);
    solver->setIterationHook([&](XpbdParticles& p, const XpbdIterationInfo& info) {
        inner(p, info);
        if (info.velocityPass) return;
        run.contacts += col->stats().contacts;
        if (info.iteration == 0) {
            run.tested += col->stats().trianglesTested;
            run.listsMade += col->stats().reachListMade ? 1 : 0;
        }
    });
    for (int f = 0; f < frames; ++f) {
        const double u = double(f) / frames;
        const double lift = (f > frames / 2 && f < frames / 2 + 5) ? 0.01 : 0.0;
        tool.setPose(translation(Vec3(0.01 + 0.04 * u, 0.02 + 0.005 * std::sin(6 * u), 0.012 + r - 0.001 + lift)));
        EXPECT_TRUE(solver->step().finite);
        run.frames.push_back(solver->positions());
    }
    return run;
}

} // namespace

// The reach list (CollisionSettings::reachListMargin) only spares the broad phase the triangles
// that cannot reach the tool while the surface and the tool stay within the margin: a sphere
// dragged across a slab, lifted and put down, gives bit-identical frames with the list and with
// every triangle tested every step, for every method, while the list tests a fraction of the
// triangles and is made anew as the tool moves on.
TEST(CollisionHook, ReachListGivesTheResultsOfTestingEveryTriangle) {
    const Slab s = slab(Vec3(0.06, 0.04, 0.012), {20, 12, 4});
    for (CollisionMethod method : {CollisionMethod::Circumsphere, CollisionMethod::BoundingSphere,
                                   CollisionMethod::Polygon, CollisionMethod::PolygonFeatures}) {
        SCOPED_TRACE(toString(method));
        const int frames = 40;
        const SweepRun every = sweepingSphere(s, method, 0.0, frames);
        const SweepRun listed = sweepingSphere(s, method, 1e-4, frames);
        EXPECT_GT(every.contacts, 0);
        EXPECT_EQ(listed.contacts, every.contacts);
        for (int f = 0; f < frames; ++f)
            ASSERT_TRUE(identical(every.frames[f], listed.frames[f])) << "frame " << f;
        EXPECT_EQ(every.listsMade, 0);
        EXPECT_GT(listed.listsMade, 3);               // the tool moves ~1 mm per frame
        EXPECT_LT(listed.listsMade, frames * 20 / 2); // but most steps reuse the list
        EXPECT_LT(listed.tested * 2, every.tested);   // far fewer triangles looked at
    }
}

TEST(CollisionHook, ReachListMarginIsValidated) {
    CollisionSettings cs;
    cs.reachListMargin = -1e-3;
    EXPECT_EQ(validate(cs), "reach list margin must be finite and >= 0");
    cs.reachListMargin = std::nan("");
    EXPECT_FALSE(validate(cs).empty());
    cs.reachListMargin = 0;
    EXPECT_TRUE(validate(cs).empty());
}

// A list made while a vertex was not finite (a step the solver then rolls back) still gives the
// candidates of testing every triangle once the positions are finite again: the triangles of a
// non-finite vertex go onto the list, and a NaN never passes the allowance test.
TEST(CollisionHook, ReachListMadeOverANonFiniteVertexMissesNothing) {
    const Slab s = slab(Vec3(0.06, 0.04, 0.012), {20, 12, 4});
    CollisionSettings every, listed;
    every.reachListMargin = 0;
    for (CollisionMethod method : {CollisionMethod::Circumsphere, CollisionMethod::Polygon}) {
        SCOPED_TRACE(toString(method));
        every.method = listed.method = method;
        auto a = CollisionSolver::create(CollisionSurfaceDesc::fromTetMesh(*s.mesh, s.invMass), every);
        auto b = CollisionSolver::create(CollisionSurfaceDesc::fromTetMesh(*s.mesh, s.invMass), listed);
        const std::vector<Vec3> x = s.mesh->positions();
        // A top vertex 15 mm (along y) from where the tool waits, just above the top.
        int32_t v = 0;
        const Vec3 from(0.03, 0.01, 0.012);
        for (int32_t k = 0; k < static_cast<int32_t>(x.size()); ++k)
            if ((x[k] - from).norm() < (x[v] - from).norm()) v = k;
        const Vec3 under = x[v] + Vec3(0, 0.015, 0);
        ToolShape tool = ToolShape::sphere(0.003);
        tool.setPose(translation(under + Vec3(0, 0, 0.0028)));
        std::vector<Vec3> broken = x;
        broken[v].y() = std::nan(""); // the list is made over it (a step the solver rolls back)
        b->beginStep(broken, tool, 1e-3);
        ASSERT_TRUE(b->stats().reachListMade);
        // Then, finite again, the vertex slides along y (the NaN's axis only) under the tool.
        for (double u : {0.0, 0.5, 1.0}) {
            std::vector<Vec3> moved = x;
            moved[v] = x[v] + u * (under - x[v]);
            a->beginStep(moved, tool, 1e-3);
            b->beginStep(moved, tool, 1e-3);
            EXPECT_FALSE(b->stats().reachListMade) << "the tool did not move";
            EXPECT_EQ(a->stats().candidates, b->stats().candidates) << u;
            if (u == 1.0) EXPECT_GT(a->stats().candidates, 0);
        }
    }
}
