// Stability of tool–tissue collision [A §5.2] coupled to XPBD: fast tools (0.5 and 2 m/s), a tool
// that starts inside the tissue, degenerate and sliver surface triangles. Every frame is checked
// for finite values, bounded energy and capped displacement; repeat runs must be identical, and
// the circumsphere method must not let the tissue through the tool at 0.5 m/s.
#include "sim/collision/collision_solver.hpp"
#include "sim/mesh/generators.hpp"
#include "sim/scene/tool_probe.hpp"
#include "sim/xpbd/xpbd_solver.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

using namespace viscera::sim;

namespace {

const CollisionMethod kAllMethods[] = {CollisionMethod::Circumsphere, CollisionMethod::BoundingSphere,
                                       CollisionMethod::Polygon, CollisionMethod::PolygonFeatures};

constexpr double kFrame = 1.0 / 60.0, kTop = 0.02, kR = 0.008;
constexpr int kSubsteps = 20;

struct Rig {
    std::unique_ptr<TetMesh> mesh;
    std::vector<int32_t> fixed, top;
    std::unique_ptr<XpbdSolver> solver;
    std::unique_ptr<CollisionSolver> collision;
    ToolShape tool = ToolShape::capsule(0.02, kR);
};

/// inIteration: the solver runs kSubsteps substeps per step() with the contacts inside its
/// iterations (makeCollisionHook, the tool pose set once per frame); otherwise one substep per
/// step() and stepWithCollision.
Rig rig(CollisionMethod method, bool inIteration, int iterations = 2, bool safeCone = true) {
    Rig r;
    r.mesh = makeBoxTetMesh({Vec3::Zero(), Vec3(0.06, 0.06, kTop), {8, 8, 3}});
    r.mesh->requireLevel(3);
    for (int32_t v = 0; v < static_cast<int32_t>(r.mesh->vertexCount()); ++v) {
        if (r.mesh->positions()[v].z() < 1e-9) r.fixed.push_back(v);
        if (r.mesh->positions()[v].z() > kTop - 1e-9) r.top.push_back(v);
    }
    Material m;
    m.youngsModulus = 10000;
    m.poissonRatio = 0.3;
    XpbdSettings s;
    s.dt = inIteration ? kFrame : kFrame / kSubsteps;
    s.substeps = inIteration ? kSubsteps : 1;
    s.iterations = iterations;
    s.threads = 1;
    r.solver = XpbdSolver::create(*r.mesh, m, r.fixed, s);
    const auto mass = lumpedMasses(*r.mesh, m.density, r.fixed);
    std::vector<double> w(mass.size());
    for (size_t i = 0; i < w.size(); ++i)
        w[i] = mass[i] > 0 ? 1 / mass[i] : 0;
    CollisionSettings cs;
    cs.method = method;
    cs.safeConeOnly = safeCone;
    r.collision = CollisionSolver::create(CollisionSurfaceDesc::fromTetMesh(*r.mesh, w), cs);
    return r;
}

ToolShape::Pose pose(double x, double z) {
    ToolShape::Pose p = ToolShape::Pose::Identity();
    p.linear() = Eigen::AngleAxisd(M_PI / 2, Vec3::UnitZ()).toRotationMatrix();
    p.translation() = Vec3(x, 0.03, z);
    return p;
}

struct Outcome {
    std::vector<Vec3> finalPositions;
    int tunnelled = 0; ///< most top vertices through the tool in one frame
    double maxEnergy = 0;
};

/// Top vertices deeper than 1 mm inside the tool or above its axis within its footprint.
int tunnelled(const Rig& r) {
    const Capsule& c = r.tool.parts()[0];
    int n = 0;
    for (int32_t v : r.top) {
        const Vec3& p = r.solver->positions()[v];
        const bool over = p.z() > c.a.z() && std::abs(p.x() - c.a.x()) < kR && p.y() > std::min(c.a.y(), c.b.y()) &&
                          p.y() < std::max(c.a.y(), c.b.y());
        n += r.tool.signedDistance(p) < -1e-3 || over;
    }
    return n;
}

/// Press to `depth` (from `zStart`), then slide 3 cm along x at `speed`, checking every frame.
Outcome run(CollisionMethod method, double speed, double zStart, double depth, double energyBound = 0.05,
            double extraDisplacement = 0.01, bool inIteration = false) {
    Rig r = rig(method, inIteration);
    if (inIteration) r.solver->setIterationHook(makeCollisionHook(*r.collision, r.tool));
    Outcome o;
    const double zPress = kTop + kR - depth;
    std::vector<std::pair<double, double>> keys;
    for (int f = 1; f <= 8; ++f)
        keys.push_back({0.015, zStart + (zPress - zStart) * f / 8.0});
    for (int f = 0; f < 5; ++f)
        keys.push_back({0.015, zPress});
    const int slide = static_cast<int>(std::ceil(0.03 / (speed * kFrame)));
    for (int f = 1; f <= slide; ++f)
        keys.push_back({0.015 + std::min(0.03, speed * kFrame * f), zPress});
    for (int f = 0; f < 10; ++f)
        keys.push_back({0.045, zPress});
    ToolShape::Pose prev = pose(0.015, zStart);
    r.tool.setPose(prev);
    for (size_t f = 0; f < keys.size(); ++f) {
        const ToolShape::Pose next = pose(keys[f].first, keys[f].second);
        CollisionFrameResult fr;
        if (inIteration) {
            r.tool.setPose(next); // device sample, held for the frame
            const StepStats st = r.solver->step();
            fr.finite = st.finite;
            fr.maxDisplacement = st.maxDisplacement;
        } else {
            fr = stepWithCollision(*r.solver, *r.collision, r.tool, prev, next, kSubsteps, 2);
        }
        prev = next;
        EXPECT_TRUE(fr.finite) << "frame " << f;
        for (const Vec3& p : r.solver->positions())
            EXPECT_TRUE(p.allFinite()) << "frame " << f;
        const double e = r.solver->elasticEnergy() + r.solver->kineticEnergy() + r.solver->potentialEnergy();
        EXPECT_TRUE(std::isfinite(e)) << "frame " << f;
        // The slab weighs 75 g; a few mm of indentation stores millijoules.
        EXPECT_LT(e, energyBound) << "frame " << f;
        o.maxEnergy = std::max(o.maxEnergy, e);
        // Capped motion: no node moves more than the tool's frame travel plus a radius.
        EXPECT_LT(fr.maxDisplacement, speed * kFrame + extraDisplacement) << "frame " << f;
        o.tunnelled = std::max(o.tunnelled, tunnelled(r));
        if (::testing::Test::HasFailure()) break;
    }
    o.finalPositions = r.solver->positions();
    return o;
}

/// A tool pressed 5 mm into the slab over 8 frames (contacts inside the XPBD iteration), then
/// held for 100 frames: the mean per-frame move of the contact vertices over the last 20, m.
double heldJitter(CollisionMethod method, int iterations, bool safeCone) {
    Rig r = rig(method, true, iterations, safeCone);
    r.solver->setIterationHook(makeCollisionHook(*r.collision, r.tool));
    const double zStart = kTop + kR + 0.002, zPress = kTop + kR - 0.005;
    r.tool.setPose(pose(0.03, zStart));
    std::vector<Vec3> last = r.solver->positions();
    double sum = 0;
    int frames = 0;
    for (int f = 1; f <= 108; ++f) {
        r.tool.setPose(pose(0.03, zStart + (zPress - zStart) * std::min(f, 8) / 8.0));
        const StepStats st = r.solver->step();
        EXPECT_TRUE(st.finite) << "frame " << f;
        const std::vector<Vec3>& x = r.solver->positions();
        const std::vector<int32_t>& cv = r.collision->contactVertices();
        if (f > 88 && !cv.empty()) {
            double move = 0;
            for (int32_t v : cv)
                move += (x[v] - last[v]).norm();
            sum += move / cv.size();
            ++frames;
        }
        last = x;
    }
    EXPECT_EQ(frames, 20) << "the tool lost contact";
    return frames ? sum / frames : 0;
}

} // namespace

// A held tool must come to rest on the circumspheres at few iterations (measured 5.6e-10 m per
// frame at 1, 2 and 5 iterations; the other methods 3e-11 to 2e-10). Without the safe-cone test
// the spheres around the dent reach under it and the surface keeps chattering (3.9e-5 to
// 7.7e-5 m per frame): that run shows the check detects chatter.
TEST(CollisionStability, CircumsphereUnderAHeldToolComesToRest) {
    for (int iterations : {1, 2, 5}) {
        SCOPED_TRACE(std::to_string(iterations) + " iterations");
        const double cone = heldJitter(CollisionMethod::Circumsphere, iterations, true);
        const double whole = heldJitter(CollisionMethod::Circumsphere, iterations, false);
        RecordProperty("jitter_cone_it" + std::to_string(iterations), std::to_string(cone));
        RecordProperty("jitter_whole_sphere_it" + std::to_string(iterations), std::to_string(whole));
        std::printf("held tool, %d iterations: mean move per frame %.3g m (safe cone), %.3g m "
                    "(whole sphere)\n",
                    iterations, cone, whole);
        EXPECT_LT(cone, 1e-8);
        EXPECT_GT(whole, 100 * cone);
    }
}

TEST(CollisionStability, CircumsphereAtHalfMetrePerSecondDoesNotTunnelAndRepeats) {
    const Outcome a = run(CollisionMethod::Circumsphere, 0.5, kTop + kR + 0.002, 0.005);
    EXPECT_EQ(a.tunnelled, 0);
    const Outcome b = run(CollisionMethod::Circumsphere, 0.5, kTop + kR + 0.002, 0.005);
    EXPECT_EQ(a.finalPositions, b.finalPositions);
}

TEST(CollisionStability, AllMethodsStayFiniteAtTwoMetresPerSecond) {
    for (CollisionMethod m : kAllMethods) {
        SCOPED_TRACE(toString(m));
        const Outcome a = run(m, 2.0, kTop + kR + 0.002, 0.005);
        const Outcome b = run(m, 2.0, kTop + kR + 0.002, 0.005);
        EXPECT_EQ(a.finalPositions, b.finalPositions);
    }
}

TEST(CollisionStability, ToolStartingInsideTheTissue) {
    for (CollisionMethod m : kAllMethods) {
        SCOPED_TRACE(toString(m));
        // Axis 4 mm below the top surface from the first frame on.
        // 12 mm of a 20 mm slab displaced at once: bounded, not small.
        // Nodes jump out of the tool in the first frames and rebound.
        run(m, 0.5, kTop - 0.004, 0.012, 0.5, 0.04); // measured: up to 30 mm in frame 0
    }
}

// Contacts inside the XPBD iteration, tool pose once per frame (it jumps 33 mm per frame at
// 2 m/s, through the tissue, which is shoved aside over the frame's substeps): every frame
// finite, energy and displacement bounded (measured: up to 0.068 J with the bounding sphere in
// the first slide frame), repeat runs bit-identical.
TEST(CollisionStability, InIterationAllMethodsStayFiniteAtTwoMetresPerSecond) {
    for (CollisionMethod m : kAllMethods) {
        SCOPED_TRACE(toString(m));
        const Outcome a = run(m, 2.0, kTop + kR + 0.002, 0.005, 0.5, 0.04, true);
        const Outcome b = run(m, 2.0, kTop + kR + 0.002, 0.005, 0.5, 0.04, true);
        EXPECT_EQ(a.finalPositions, b.finalPositions);
    }
}

TEST(CollisionStability, InIterationToolStartingInsideTheTissue) {
    for (CollisionMethod m : kAllMethods) {
        SCOPED_TRACE(toString(m));
        run(m, 0.5, kTop - 0.004, 0.012, 0.5, 0.04, true);
    }
}

TEST(CollisionStability, DegenerateAndSliverTriangles) {
    CollisionSurfaceDesc d;
    d.restPositions = {Vec3(0, 0, 0),       Vec3(0.01, 0, 0),    Vec3(0.02, 0, 0),    // collinear
                       Vec3(0, 0.01, 0),    Vec3(0.01, 0.01, 0), Vec3(0.01, 0.01, 0), // coincident
                       Vec3(0.005, 1e-9, 0)};                                         // sliver apex
    d.triangles = {{0, 1, 2}, {3, 4, 5}, {0, 1, 6}, {0, 1, 4}};
    d.inverseMass.assign(d.restPositions.size(), 10.0);
    for (CollisionMethod m : kAllMethods) {
        SCOPED_TRACE(toString(m));
        CollisionSettings s;
        s.method = m;
        auto col = CollisionSolver::create(d, s);
        ToolShape tool = ToolShape::sphere(0.006);
        std::vector<Vec3> x = d.restPositions;
        for (int step = 0; step < 40; ++step) {
            ToolShape::Pose p = ToolShape::Pose::Identity();
            p.translation() = Vec3(0.001 * step, 0.005, 0.004 - 0.0002 * step);
            tool.setPose(p);
            col->beginStep(x, tool, 1e-3);
            for (int k = 0; k < 3; ++k)
                col->iterate(x, tool);
            for (const Vec3& v : x)
                ASSERT_TRUE(v.allFinite()) << "step " << step;
            EXPECT_LT(col->stats().maxCorrection, 0.02) << "step " << step;
        }
    }
}
