#include "sim/mesh/generators.hpp"
#include "sim/scene/scene.hpp"
#include "sim/scene/world.hpp"
#include "sim/util/error.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

using namespace viscera::sim;
using ::testing::HasSubstr;

namespace {
SceneDesc slabScene() {
    SceneDesc s;
    s.instructions = "watch";
    s.xpbd.substeps = 20; // what the load-time stability check asks for at 3 kPa on 5 mm cells
    BodyDesc b;
    b.name = "slab";
    b.meshPath = "meshes/slab.vtet";
    b.fixedNodes = {0, 1, 2};
    s.bodies.push_back(b);
    return s;
}
std::string parseError(const std::string& text) {
    try {
        parseScene(text, "scene.json");
    } catch (const viscera::InputError& e) {
        return e.what();
    }
    return "accepted";
}
std::vector<std::unique_ptr<TetMesh>> oneMesh() {
    std::vector<std::unique_ptr<TetMesh>> v;
    v.push_back(makeBoxTetMesh({}));
    return v;
}
} // namespace

TEST(Scene, RoundTrip) {
    SceneDesc s = slabScene();
    s.xpbd.substeps = 17;
    SceneDesc back = parseScene(formatScene(s), "scene.json");
    EXPECT_EQ(back.instructions, "watch");
    EXPECT_EQ(back.xpbd.substeps, 17);
    EXPECT_EQ(back.xpbd.gravity, s.xpbd.gravity);
    ASSERT_EQ(back.bodies.size(), 1u);
    EXPECT_EQ(back.bodies[0].fixedNodes, s.bodies[0].fixedNodes);
    EXPECT_EQ(back.bodies[0].material.poissonRatio, s.bodies[0].material.poissonRatio);
}

TEST(Scene, StepsAreOrderedPrintableTextOfBoundedCount) {
    SceneDesc s = slabScene();
    EXPECT_TRUE(parseScene(formatScene(s), "scene.json").steps.empty()); // optional, default none
    EXPECT_EQ(formatScene(s).find("\"steps\""), std::string::npos);      // none: not written
    s.steps = {"Lift the fundus", "Clip the duct twice — é", "Cut between the clips"};
    EXPECT_EQ(parseScene(formatScene(s), "scene.json").steps, s.steps); // order kept

    const std::string head = R"({"solver": {"type": "xpbd", "substeps": 20}, "bodies": [{"name": "a",
        "mesh": "m.vtet", "material": {"model": "neo_hookean", "youngs_modulus": 1000, "poisson_ratio": 0.3,
        "density": 1000}}], "steps": )";
    EXPECT_EQ(parseError(head + R"(["one", "two"]})"), "accepted");
    EXPECT_THAT(parseError(head + R"("one"})"), HasSubstr("scene.json: steps: must be an array"));
    EXPECT_THAT(parseError(head + R"(["one", 2]})"), HasSubstr("scene.json: steps[1]: must be a string"));
    EXPECT_THAT(parseError(head + R"(["one", ""]})"), HasSubstr("scene.json: steps[1]: must not be empty"));
    EXPECT_THAT(parseError(head + R"(["one", "a\u001bb"]})"),
                HasSubstr("scene.json: steps[1]: must be printable text: control character U+001B"));
    EXPECT_THAT(parseError(head + R"(["a\nb"]})"), HasSubstr("steps[0]: must be printable text"));
    const std::string longest(kMaxStepBytes, 'x');
    EXPECT_EQ(parseError(head + "[\"" + longest + "\"]}"), "accepted");
    EXPECT_THAT(parseError(head + "[\"" + longest + "x\"]}"),
                HasSubstr("steps[0]: must be at most " + std::to_string(kMaxStepBytes) + " bytes"));
    std::string many = "[";
    for (size_t k = 0; k <= kMaxSteps; ++k)
        many += (k ? ", \"" : "\"") + std::to_string(k) + "\"";
    EXPECT_THAT(parseError(head + many + "]}"),
                HasSubstr("scene.json: steps: must have 0 to " + std::to_string(kMaxSteps) + " elements"));
}

TEST(Scene, RenderBlockAndPrimalCorrectionRoundTrip) {
    SceneDesc s = slabScene();
    s.render = R"({"post":{"tone_mapping":false},"sss":false})";
    s.xpbd.primalCorrection = true;
    const SceneDesc back = parseScene(formatScene(s), "scene.json");
    EXPECT_EQ(back.render, s.render);
    EXPECT_TRUE(back.xpbd.primalCorrection);
    EXPECT_FALSE(parseScene(formatScene(slabScene()), "scene.json").xpbd.primalCorrection);
    EXPECT_THAT(parseError(R"({"solver": {"type": "xpbd"}, "render": [1], "bodies": []})"),
                HasSubstr("scene.json: render: must be an object"));
    EXPECT_THAT(parseError(R"({"solver": {"type": "xpbd", "primal_correction": 1}, "bodies": []})"),
                HasSubstr("solver.primal_correction: must be true or false"));
    EXPECT_THAT(parseError(R"({"solver": {"type": "xpbd", "inertia_scaling": 0.5}, "bodies": []})"),
                HasSubstr("solver.inertia_scaling"));
}

TEST(Scene, ErrorsNameTheField) {
    EXPECT_THAT(parseError("{"), HasSubstr("scene.json: invalid JSON ("));
    EXPECT_THAT(parseError("{}"), HasSubstr("scene.json: solver: required field is missing"));
    EXPECT_THAT(parseError(R"({"solver": {"type": "mpm"}, "bodies": []})"),
                HasSubstr("solver.type: 'mpm' is not a supported solver (xpbd, fem)"));
    EXPECT_THAT(parseError(R"({"solver": {"type": "xpbd", "substeps": 0}, "bodies": []})"),
                HasSubstr("solver.substeps: must be an integer in [1, 1000]"));
    EXPECT_THAT(parseError(R"({"solver": {"type": "xpbd"}, "bodies": []})"), HasSubstr("bodies: must not be empty"));
    EXPECT_THAT(parseError(R"({"solver": {"type": "xpbd"}, "bodies": [{"name": "a", "mesh": "m.vtet",
        "material": {"model": "neo_hookean", "youngs_modulus": 1000, "poisson_ratio": 0.7, "density": 1000}}]})"),
                HasSubstr("bodies[0].material.poisson_ratio: must be in [0, 0.5)"));
    EXPECT_THAT(parseError(R"({"solver": {"type": "xpbd"}, "bodies": [{"name": "a", "mesh": "m.vtet",
        "material": {"model": "neo_hookean", "youngs_modulus": 1000, "poisson_ratio": 0.3, "density": 1000},
        "fixed_nodes": [1, -2]}]})"),
                HasSubstr("bodies[0].fixed_nodes[1]: must not be negative"));
}

TEST(World, AssemblesOnlyDeclaredSubsystems) {
    SceneDesc s = slabScene();
    auto w = World::assemble(s, oneMesh(), {}, {"gravity", "xpbd"}, "case");
    EXPECT_EQ(w->activeSubsystems(), (std::vector<std::string>{"gravity", "xpbd"}));
    FrameRecord r = w->step();
    EXPECT_TRUE(r.finite);
    EXPECT_EQ(r.substeps, s.xpbd.substeps);
    EXPECT_GT(w->invariants().maxStepDisplacement, 0.0);

    s.xpbd.gravity.setZero();
    auto still = World::assemble(s, oneMesh(), {}, {"xpbd"}, "case");
    EXPECT_EQ(still->activeSubsystems(), std::vector<std::string>{"xpbd"});
    still->step();
    EXPECT_LT(still->invariants().maxStepDisplacement, 1e-12);
}

TEST(World, RefusesWhatItCannotRun) {
    auto err = [](const SceneDesc& s, std::vector<std::string> f) {
        try {
            World::assemble(s, oneMesh(), {}, f, "c.vcase: manifest.json");
        } catch (const viscera::InputError& e) {
            return std::string(e.what());
        }
        return std::string("accepted");
    };
    SceneDesc s = slabScene();
    EXPECT_THAT(err(s, {"xpbd", "gravity", "haptics"}),
                HasSubstr("c.vcase: manifest.json: features: 'haptics' is not supported by this player"));
    EXPECT_THAT(err(s, {"gravity"}), HasSubstr("the scene uses solver 'xpbd' but the manifest does not declare it"));
    EXPECT_THAT(err(s, {"xpbd"}), HasSubstr("does not declare 'gravity'"));
    s.bodies[0].fixedNodes = {100000};
    const std::string bad = err(s, {"xpbd", "gravity"});
    EXPECT_THAT(bad, HasSubstr("cannot be simulated stably"));
    EXPECT_THAT(bad, HasSubstr("fixed node 100000"));
}

TEST(World, RefusesAFrameOverTheWorkBudgetBeforeAllocatingIt) {
    // 1,000 substeps x 1,000 iterations, each within its own limit, on a 1,000-tet box: 1e9 constraint
    // solves per frame (hours per second of simulation, gigabytes before the first frame).
    SceneDesc s = slabScene();
    s.xpbd.substeps = XpbdLimits::maxSubsteps;
    s.xpbd.iterations = XpbdLimits::maxIterations;
    auto meshes = oneMesh();
    const size_t tets = meshes[0]->tetCount();
    try {
        World::assemble(s, std::move(meshes), {}, {"gravity", "xpbd"}, "c.vcase: scene.json");
        FAIL() << "assembled";
    } catch (const viscera::InputError& e) {
        EXPECT_EQ(
            std::string(e.what()), "c.vcase: scene.json: solver: substeps 1000 x iterations 1000 x " +
                                       std::to_string(tets) + " elements = " +
                                       [&] {
                                           char t[32];
                                           std::snprintf(t, sizeof t, "%.3g", 1e6 * double(tets));
                                           return std::string(t);
                                       }() +
                                       " constraint solves per frame, more than the work limit of "
                                       "1e+08 (about a second per frame); lower substeps or iterations");
    }
    // The budget is a product: the same substeps with one iteration fits.
    s.xpbd.iterations = 1;
    EXPECT_NO_THROW(World::assemble(s, oneMesh(), {}, {"gravity", "xpbd"}, "c.vcase: scene.json"));
}
