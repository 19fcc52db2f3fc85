// World's bodies run through one SceneSolver: a one-body XPBD scene, a layered XPBD scene and a
// small suturing FEM scene through the interface, bit-identical to the solvers they wrap; the
// solvers' preconditions carry their rule apart from the function name.
#include "sim/material/material.hpp"
#include "sim/mesh/generators.hpp"
#include "sim/reference/accuracy.hpp"

#include "sim/scene/fem_scene_solver.hpp"
#include "sim/scene/scene.hpp"
#include "sim/scene/world.hpp"
#include "sim/scene/xpbd_scene_solver.hpp"
#include "sim/util/error.hpp"
#include "sim/xpbd/xpbd_solver.hpp"
#include "sim/xpbd/xpbd_system.hpp"
#include <atomic>

#include "suture_fixture.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

using namespace viscera::sim;
using ::testing::HasSubstr;
using ::testing::StartsWith;

namespace {

BodyDesc slabBody(const std::string& name) {
    BodyDesc b;
    b.name = name;
    b.meshPath = "meshes/" + name + ".vtet";
    b.fixedNodes = {0, 1, 2};
    return b;
}

SceneDesc oneBodyScene() {
    SceneDesc s;
    s.xpbd.substeps = 20; // what the load-time stability check asks for at 3 kPa on 5 mm cells
    s.bodies.push_back(slabBody("slab"));
    return s;
}

std::unique_ptr<TetMesh> box(double x0) {
    return makeBoxTetMesh({Vec3(x0, 0, 0), Vec3(0.1, 0.02, 0.04), {10, 2, 4}});
}

TetBodyDesc tetBody(const BodyDesc& b, const TetMesh& mesh) {
    TetBodyDesc tb;
    tb.name = b.name;
    tb.mesh = &mesh;
    tb.model = makeConstraintModel(b.material, b.name);
    tb.density = b.material.density;
    tb.fixedNodes = b.fixedNodes;
    return tb;
}

SceneDesc femScene() {
    SceneDesc s = parseScene(suture_fixture::kScene, "scene.json");
    s.suture->trajectoryText = suture_fixture::trajectory(20, 0.0014);
    return s;
}

using suture_fixture::slabs;

} // namespace

TEST(SceneSolver, OneBodyXpbdIsTheXpbdSolverBitForBit) {
    SceneDesc s = oneBodyScene();
    s.accuracy = AccuracySampling{1, 5};
    std::vector<std::unique_ptr<TetMesh>> meshes;
    meshes.push_back(box(0));
    const std::vector<TriMesh> surfaces;
    std::unique_ptr<SceneSolver> solver = makeSceneSolver({s, meshes, surfaces, "case"});
    ASSERT_NE(dynamic_cast<XpbdSceneSolver*>(solver.get()), nullptr);
    EXPECT_EQ(solver->interaction(), nullptr);
    EXPECT_EQ(solver->suture(), nullptr);

    auto ref = XpbdSolver::create(tetBody(s.bodies[0], *meshes[0]), s.xpbd);
    std::vector<AccuracyRecord> acc;
    for (int f = 0; f < 4; ++f) {
        const FrameClock clock{f, f * s.xpbd.dt, s.xpbd.dt};
        solver->sampleAccuracy(clock, acc);
        // The same measurement on the reference solver: the same figures (wall times aside).
        const AccuracyTrace xpbd = measureXpbd(*ref, 5), newton = measureNewton(*ref);
        ASSERT_EQ(acc.size(), 2u * (f + 1));
        EXPECT_EQ(acc[2 * f].iterations, xpbd.iterations);
        EXPECT_EQ(acc[2 * f].relError, xpbd.relError);
        EXPECT_EQ(acc[2 * f + 1].relError, newton.relError);
        const StepStats st = solver->step(clock);
        EXPECT_TRUE(solver->recordFrame(clock));
        const StepStats rs = ref->step();
        EXPECT_EQ(st.substeps, rs.substeps);
        EXPECT_EQ(st.iterations, rs.iterations);
        EXPECT_EQ(st.maxDisplacement, rs.maxDisplacement);
        EXPECT_EQ(st.finite, rs.finite);
        ASSERT_EQ(solver->positions(0), ref->positions()) << f;
        ASSERT_EQ(solver->velocities(0), ref->velocities()) << f;
        EXPECT_EQ(solver->totalEnergy(), ref->elasticEnergy() + ref->kineticEnergy() + ref->potentialEnergy());
    }
    ASSERT_EQ(acc.size(), 8u); // xpbd and newton on each call
    // A sampler stopping sets the cancel flag: the measurement in progress records nothing.
    std::atomic<bool> cancel{true};
    solver->setAccuracyCancel(&cancel);
    solver->sampleAccuracy({4, 4 * s.xpbd.dt, s.xpbd.dt}, acc);
    EXPECT_EQ(acc.size(), 8u) << "a cancelled sample is not recorded";
    cancel = false;
    solver->sampleAccuracy({4, 4 * s.xpbd.dt, s.xpbd.dt}, acc);
    EXPECT_EQ(acc.size(), 10u);
    acc.resize(8);
    solver->setAccuracyCancel(nullptr);
    EXPECT_EQ(acc[0].solver, "xpbd");
    EXPECT_EQ(acc[1].solver, "newton");
    EXPECT_EQ(acc[2].frame, 1);
    EXPECT_EQ(acc[3].solver, "newton");
    EXPECT_FALSE(acc[0].relError.empty());

    // setState through the interface is the solver's setState.
    std::vector<Vec3> x = ref->positions(), v = ref->velocities();
    x[5].z() += 1e-4;
    solver->setState(0, x, v);
    ref->setState(x, v);
    solver->step({4, 0, s.xpbd.dt});
    ref->step();
    EXPECT_EQ(solver->positions(0), ref->positions());
    v.pop_back();
    EXPECT_THROW(solver->setState(0, x, v), std::invalid_argument);
}

TEST(SceneSolver, LayeredXpbdIsTheXpbdSystemBitForBit) {
    SceneDesc s = oneBodyScene();
    s.bodies.push_back(slabBody("second"));
    std::vector<std::unique_ptr<TetMesh>> meshes;
    meshes.push_back(box(0));
    meshes.push_back(box(0.2));
    const std::vector<TriMesh> surfaces;
    std::unique_ptr<SceneSolver> solver = makeSceneSolver({s, meshes, surfaces, "case"});
    ASSERT_NE(dynamic_cast<XpbdSceneSolver*>(solver.get()), nullptr);
    XpbdSystemDesc desc;
    for (size_t i = 0; i < 2; ++i)
        desc.tetBodies.push_back(tetBody(s.bodies[i], *meshes[i]));
    auto ref = XpbdSystem::create(desc, s.xpbd);
    std::vector<AccuracyRecord> acc;
    for (int f = 0; f < 3; ++f) {
        const FrameClock clock{f, f * s.xpbd.dt, s.xpbd.dt};
        solver->sampleAccuracy(clock, acc); // not sampled on layered scenes
        const StepStats st = solver->step(clock);
        const StepStats rs = ref->step();
        EXPECT_EQ(st.maxDisplacement, rs.maxDisplacement);
        for (size_t b = 0; b < 2; ++b)
            ASSERT_EQ(solver->positions(b), ref->tetPositions(b)) << f;
        EXPECT_EQ(solver->totalEnergy(), ref->elasticEnergy() + ref->kineticEnergy() + ref->potentialEnergy());
    }
    EXPECT_TRUE(acc.empty());

    // The World runs the same.
    std::vector<std::unique_ptr<TetMesh>> again;
    again.push_back(box(0));
    again.push_back(box(0.2));
    auto w = World::assemble(s, std::move(again), {}, requiredFeatures(s), "case");
    for (int f = 0; f < 3; ++f)
        w->step();
    for (size_t b = 0; b < 2; ++b)
        EXPECT_EQ(w->positions(b), ref->tetPositions(b));
    EXPECT_FALSE(w->hasSuture());
    EXPECT_TRUE(w->sutureFrames().empty());
}

TEST(SceneSolver, FemRunsTheSuturingAndReportsIt) {
    const SceneDesc s = femScene();
    const std::vector<std::unique_ptr<TetMesh>> meshes = slabs();
    const std::vector<TriMesh> surfaces;
    std::unique_ptr<SceneSolver> solver = makeSceneSolver({s, meshes, surfaces, "case"});
    ASSERT_NE(dynamic_cast<FemSceneSolver*>(solver.get()), nullptr);
    const SutureReport* report = solver->suture();
    ASSERT_NE(report, nullptr);
    EXPECT_EQ(solver->totalEnergy(), 0.0); // at rest
    std::vector<AccuracyRecord> acc;
    for (int f = 0; f < 12; ++f) {
        const FrameClock clock{f, f * s.xpbd.dt, s.xpbd.dt};
        solver->sampleAccuracy(clock, acc);
        const StepStats st = solver->step(clock);
        ASSERT_TRUE(st.finite) << f;
        EXPECT_EQ(st.substeps, 1);
        EXPECT_TRUE(solver->recordFrame(clock));
    }
    EXPECT_TRUE(acc.empty());
    ASSERT_EQ(report->frames().size(), 12u);
    EXPECT_GE(report->frames()[0].maxGap, 0.0); // gauge sampled every 10th frame
    EXPECT_EQ(report->frames()[1].maxGap, -1.0);
    EXPECT_GE(report->frames()[10].maxGap, 0.0);
    const SutureSummary sum = report->summary();
    EXPECT_TRUE(sum.gauge && sum.finite);
    EXPECT_NEAR(sum.initialGap, 0.001, 1e-9);
    EXPECT_EQ(solver->positions(1).size(), meshes[1]->vertexCount());
    EXPECT_EQ(solver->velocities(1), std::vector<Vec3>(meshes[1]->vertexCount(), Vec3::Zero()));
    EXPECT_THROW(solver->surfacePositions(0), std::out_of_range);
    EXPECT_THROW(solver->setState(0, solver->positions(0), solver->velocities(0)), std::invalid_argument);

    // The World reports the solver's figures: same positions, same frames.
    auto w = World::assemble(s, slabs(), {}, requiredFeatures(s), "case");
    EXPECT_EQ(w->invariants().maxEnergy, 0.0);
    for (int f = 0; f < 12; ++f)
        w->step();
    ASSERT_TRUE(w->hasSuture());
    for (size_t b = 0; b < 2; ++b)
        EXPECT_EQ(w->positions(b), solver->positions(b));
    ASSERT_EQ(w->sutureFrames().size(), 12u);
    EXPECT_EQ(w->sutureFrames()[11].threadTension, report->frames()[11].threadTension);
    EXPECT_EQ(w->sutureSummary().finalGap, sum.finalGap);
}

TEST(SceneSolver, RejectsWhatTheBackEndCannotRun) {
    auto err = [](const SceneDesc& s, std::vector<std::unique_ptr<TetMesh>> meshes) {
        try {
            const std::vector<TriMesh> surfaces;
            makeSceneSolver({s, meshes, surfaces, "c.vcase"});
        } catch (const viscera::InputError& e) {
            return std::string(e.what());
        }
        return std::string("accepted");
    };
    std::vector<std::unique_ptr<TetMesh>> one;
    one.push_back(box(0));
    SceneDesc s = oneBodyScene();
    s.bodies[0].fixedNodes = {100000};
    // One body: the rule alone, no function name (the XpbdSolver's message carries it).
    const std::string nv = std::to_string(one[0]->vertexCount());
    EXPECT_EQ(err(s, std::move(one)),
              "c.vcase: scene cannot be simulated stably: fixed node 100000 is out of range (mesh has " + nv +
                  " vertices)");
    s.bodies.push_back(slabBody("second"));
    std::vector<std::unique_ptr<TetMesh>> two;
    two.push_back(box(0));
    two.push_back(box(0.2));
    EXPECT_EQ(err(s, std::move(two)), "c.vcase: scene cannot be simulated stably: tet body 0 ('slab'): fixed node "
                                      "100000 is out of range (mesh has " +
                                          nv + " vertices)");
    SceneDesc f = femScene();
    f.tools.push_back(ToolDesc{});
    EXPECT_EQ(err(f, slabs()), "c.vcase: scene: solver 'fem': haptic probes are not supported");
}

TEST(PreconditionError, KeepsTheRuleApartFromTheFunction) {
    const auto mesh = box(0);
    TetBodyDesc b = tetBody(slabBody("slab"), *mesh);
    b.fixedNodes = {100000};
    XpbdSettings st;
    st.substeps = 20;
    try {
        XpbdSolver::create(b, st);
        FAIL() << "accepted";
    } catch (const viscera::PreconditionError& e) {
        EXPECT_EQ(std::string(e.what()), "sim::XpbdSolver::create(): " + e.rule);
        EXPECT_THAT(e.rule, StartsWith("fixed node 100000 is out of range"));
    }
    XpbdSystemDesc desc;
    desc.tetBodies.push_back(b);
    try {
        XpbdSystem::create(desc, st);
        FAIL() << "accepted";
    } catch (const viscera::PreconditionError& e) {
        EXPECT_EQ(std::string(e.what()), "sim::XpbdSystem::create(): " + e.rule);
        EXPECT_THAT(e.rule, StartsWith("tet body 0 ('slab'): fixed node 100000"));
    }
    b.fixedNodes = {0};
    auto solver = XpbdSolver::create(b, st);
    try {
        solver->setState({}, {});
        FAIL() << "accepted";
    } catch (const viscera::PreconditionError& e) {
        EXPECT_EQ(std::string(e.what()), "sim::XpbdSolver::setState(): expected " +
                                             std::to_string(mesh->vertexCount()) +
                                             " positions and velocities, got 0 and 0");
        EXPECT_EQ(std::string(e.what()), "sim::XpbdSolver::setState(): " + e.rule);
    }
}

namespace {

/// A fat cantilever (6 × 2 × 2 cm, 5 mm cells, 3 kPa) with a stiffer vessel bar embedded in it
/// (4 × 0.8 × 0.8 cm, 20 kPa): the vessel's stiffness number limits the scene.
struct EmbeddedScene {
    SceneDesc scene;
    std::vector<std::unique_ptr<TetMesh>> meshes;
    explicit EmbeddedScene(int substeps) {
        scene.xpbd.substeps = substeps;
        scene.xpbd.damping = 2.0;
        meshes.push_back(makeBoxTetMesh({Vec3::Zero(), Vec3(0.06, 0.02, 0.02), {12, 4, 4}}));
        meshes.push_back(makeBoxTetMesh({Vec3(0.01, 0.006, 0.006), Vec3(0.04, 0.008, 0.008), {8, 1, 1}}));
        BodyDesc fat;
        fat.name = "fat";
        fat.meshPath = "meshes/fat.vtet";
        fat.material.youngsModulus = 3000;
        fat.material.density = 950;
        for (int32_t v = 0; v < static_cast<int32_t>(meshes[0]->vertexCount()); ++v)
            if (meshes[0]->positions()[v].x() < 1e-9) fat.fixedNodes.push_back(v);
        BodyDesc vessel;
        vessel.name = "vessel";
        vessel.meshPath = "meshes/vessel.vtet";
        vessel.material.youngsModulus = 20000;
        vessel.material.density = 1050;
        vessel.embeddedIn = "fat";
        scene.bodies = {fat, vessel};
    }
    std::vector<StabilityFigures> figures() const {
        const std::vector<TriMesh> none;
        return assessSceneStability({scene, meshes, none, "case"});
    }
};

} // namespace

TEST(SceneSolver, EmbeddedBodiesCountTheInertiaOfTheirCage) {
    // The vessel's nodes move with the fat they are tied to, so the scene rule divides its
    // stiffness number by (own + tied mass) / own mass; the body-alone figure cannot see that.
    EmbeddedScene probe(20);
    const auto scene = probe.figures();
    ASSERT_EQ(scene.size(), 2u);
    const BodyDesc& v = probe.scene.bodies[1];
    const StabilityFigures alone = assessStability(*probe.meshes[1], *makeConstraintModel(v.material, v.name),
                                                   v.material.density, {}, probe.scene.xpbd);
    EXPECT_GT(alone.maxStiffnessNumber, scene[1].maxStiffnessNumber * 1.2);
    EXPECT_GT(scene[1].maxStiffnessNumber, scene[0].maxStiffnessNumber) << "the vessel limits the scene";
    const StabilityFigures fatAlone =
        assessStability(*probe.meshes[0], *makeConstraintModel(probe.scene.bodies[0].material, "fat"),
                        probe.scene.bodies[0].material.density, {}, probe.scene.xpbd);
    EXPECT_EQ(scene[0].maxStiffnessNumber, fatAlone.maxStiffnessNumber) << "nothing is tied to the fat's nodes";

    // The World accepts the fewest substeps the scene rule asks for, and refuses one fewer with the
    // one-line message that names the body.
    const int required = std::max(scene[0].requiredSubsteps, scene[1].requiredSubsteps);
    ASSERT_LT(required, alone.requiredSubsteps) << "the tied inertia saves substeps";
    {
        EmbeddedScene fewer(required - 1);
        try {
            World::assemble(fewer.scene, std::move(fewer.meshes), {}, requiredFeatures(fewer.scene), "case");
            ADD_FAILURE() << "accepted at " << required - 1 << " substeps";
        } catch (const viscera::InputError& e) {
            EXPECT_THAT(e.what(), HasSubstr("scene cannot be simulated stably: body 'vessel': stiffness number"));
        }
    }
    // At that setting the run stays finite with bounded energy, and repeats bit for bit.
    auto run = [&] {
        EmbeddedScene at(required);
        auto w = World::assemble(at.scene, std::move(at.meshes), {}, requiredFeatures(at.scene), "case");
        return w;
    };
    auto a = run(), b = run();
    double mass = 0;
    for (size_t i = 0; i < 2; ++i)
        for (const Tet& t : a->restMesh(i).tets()) {
            const auto& x = a->restMesh(i).positions();
            mass += (i == 0 ? 950.0 : 1050.0) *
                    std::abs((x[t[1]] - x[t[0]]).dot((x[t[2]] - x[t[0]]).cross(x[t[3]] - x[t[0]]))) / 6;
        }
    const double bound = 0.05 * mass * 9.81 * 0.06; // the stability suite's 5 % of m g L
    for (int f = 0; f < 180; ++f) {
        const FrameRecord ra = a->step();
        b->step();
        ASSERT_TRUE(ra.finite) << "frame " << f;
        ASSERT_LE(a->invariants().maxEnergy, bound) << "frame " << f;
        for (size_t i = 0; i < 2; ++i)
            for (const Vec3& p : a->positions(i))
                ASSERT_TRUE(p.allFinite());
    }
    EXPECT_TRUE(a->invariants().allFinite);
    for (size_t i = 0; i < 2; ++i)
        EXPECT_EQ(a->positions(i), b->positions(i)) << "repeat runs must be bit-identical";
}

TEST(SceneSolver, InertiaScalingStabilizesTheLimitingNodesOnly) {
    // Selective inertia scaling (solver.inertia_scaling): below the substeps the vessel needs, its
    // limiting nodes get extra inertia (their weight kept) and the World accepts the scene; the
    // fat, under the limit, keeps its masses. The run stays finite with bounded energy, repeats
    // bit for bit, and settles where the unscaled scene at the rule's substeps settles.
    const auto figures = EmbeddedScene(20).figures();
    const int required = std::max(figures[0].requiredSubsteps, figures[1].requiredSubsteps);
    const int fewer = figures[0].requiredSubsteps; // the fat's own limit
    ASSERT_LT(fewer, required) << "the vessel limits the scene";
    auto assemble = [&](int substeps, double scaling) {
        EmbeddedScene at(substeps);
        at.scene.xpbd.inertiaScaling = scaling;
        return World::assemble(at.scene, std::move(at.meshes), {}, requiredFeatures(at.scene), "case");
    };
    EXPECT_THROW(assemble(fewer, 1.0), viscera::InputError);
    {
        EmbeddedScene probe(fewer);
        probe.scene.xpbd.inertiaScaling = 4;
        for (const StabilityFigures& f : probe.figures())
            EXPECT_TRUE(f.ok()) << f.maxStiffnessNumber;
        const std::vector<TriMesh> none;
        const auto solver = XpbdSceneSolver::create({probe.scene, probe.meshes, none, "case"});
        ASSERT_EQ(solver->addedInertia().size(), 2u);
        EXPECT_EQ(solver->addedInertia()[0], 0.0) << "the fat is under the limit";
        EXPECT_GT(solver->addedInertia()[1], 0.0);
        // Less than the vessel's own mass (0.04 × 0.008² m³ × 1050 kg/m³ = 2.7 g) times the cap.
        EXPECT_LT(solver->addedInertia()[1], 3 * 0.04 * 0.008 * 0.008 * 1050);
    }
    auto a = assemble(fewer, 4), b = assemble(fewer, 4), plain = assemble(required, 1);
    const double mass = (0.06 * 0.02 * 0.02 * 950 + 0.04 * 0.008 * 0.008 * 1050);
    for (int f = 0; f < 300; ++f) {
        ASSERT_TRUE(a->step().finite) << "frame " << f;
        b->step();
        plain->step();
        ASSERT_LE(a->invariants().maxEnergy, 0.05 * mass * 9.81 * 0.06) << "frame " << f;
    }
    for (size_t i = 0; i < 2; ++i)
        EXPECT_EQ(a->positions(i), b->positions(i)) << "repeat runs must be bit-identical";
    // Settled after 5 s: the sag of the scaled scene matches the plain one (weights unchanged).
    double sagA = 0, sagPlain = 0;
    for (size_t v = 0; v < a->positions(0).size(); ++v) {
        sagA = std::max(sagA, a->restMesh(0).positions()[v].z() - a->positions(0)[v].z());
        sagPlain = std::max(sagPlain, plain->restMesh(0).positions()[v].z() - plain->positions(0)[v].z());
    }
    RecordProperty("sag_scaled_um", static_cast<int>(1e6 * sagA));
    RecordProperty("sag_plain_um", static_cast<int>(1e6 * sagPlain));
    EXPECT_NEAR(sagA, sagPlain, 0.02 * sagPlain);
}

TEST(SceneSolver, InertiaScalingThatCannotSufficeIsRefusedWithTheCap) {
    EmbeddedScene at(2);
    at.scene.xpbd.inertiaScaling = 4;
    try {
        World::assemble(at.scene, std::move(at.meshes), {}, requiredFeatures(at.scene), "case");
        ADD_FAILURE() << "accepted at 2 substeps";
    } catch (const viscera::InputError& e) {
        EXPECT_THAT(e.what(), HasSubstr("scene cannot be simulated stably: body '"));
        EXPECT_THAT(e.what(), HasSubstr("(after inertia scaling up to 4x)"));
    }
}
