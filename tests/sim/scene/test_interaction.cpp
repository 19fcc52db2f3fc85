// Scene "interaction" section: parse/format, rejections, and a small layered world with a grasper,
// an energy hook and a clip applier on recorded tracks (collision, grasp, dissection, clip).
#include "sim/mesh/generators.hpp"
#include "sim/scene/scene.hpp"
#include "sim/scene/world.hpp"
#include "sim/util/error.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

using namespace viscera::sim;
using ::testing::HasSubstr;

namespace {

std::string sectionError(const std::string& text) {
    try {
        parseInteractionSection(text, "scene.json");
    } catch (const viscera::InputError& e) {
        return e.what();
    }
    return "accepted";
}

const char* kHeader = "# viscera instrument track 1\n";

// Fat pad 4 × 3 × 1 cm (bottom fixed), fascia on top, a vessel inside along x at y = 2 cm.
constexpr double kTop = 0.01;

TriMesh fasciaSheet(int nx, int ny, double sx, double sy) {
    std::vector<Vec3> p;
    for (int j = 0; j <= ny; ++j)
        for (int i = 0; i <= nx; ++i) p.emplace_back(sx * i / nx, sy * j / ny, kTop);
    std::vector<Tri> t;
    for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
            const int a = j * (nx + 1) + i, b = a + 1, c = a + nx + 1, d = c + 1;
            t.push_back({a, b, d});
            t.push_back({a, d, c});
        }
    return TriMesh::fromArrays(std::move(p), std::move(t));
}

struct Rig {
    SceneDesc scene;
    std::vector<std::unique_ptr<TetMesh>> meshes;
    std::vector<TriMesh> surfaces;
};

Rig makeRig() {
    Rig r;
    SceneDesc& s = r.scene;
    s.xpbd.substeps = 70;
    s.xpbd.damping = 2.0;
    s.xpbd.gravity = Vec3(0, 0, -9.81);
    BodyDesc fat;
    fat.name = "fat";
    fat.meshPath = "meshes/fat.vtet";
    fat.material.youngsModulus = 3000;
    fat.material.poissonRatio = 0.45;
    fat.material.density = 950;
    BoxSpec box;
    box.size = Vec3(0.04, 0.03, kTop);
    box.cells = {16, 12, 3};
    r.meshes.push_back(makeBoxTetMesh(box));
    for (int32_t v = 0; v < static_cast<int32_t>(r.meshes[0]->vertexCount()); ++v)
        if (r.meshes[0]->positions()[v].z() < 1e-9) fat.fixedNodes.push_back(v);
    s.bodies.push_back(fat);
    BodyDesc vessel;
    vessel.name = "vessel";
    vessel.meshPath = "meshes/vessel.vtet";
    vessel.material.youngsModulus = 1200;
    vessel.material.poissonRatio = 0.45;
    vessel.material.density = 1060;
    vessel.embeddedIn = "fat";
    HollowTubeSpec tube;
    tube.start = Vec3(0.004, 0.02, 0.005);
    tube.end = Vec3(0.036, 0.02, 0.005);
    tube.innerRadius = 0.001;
    tube.outerRadius = 0.0025;
    tube.slices = 12;
    tube.layers = 1;
    tube.rings = 8;
    r.meshes.push_back(makeHollowTubeTetMesh(tube));
    s.bodies.push_back(vessel);
    SurfaceDesc fascia;
    fascia.name = "fascia";
    fascia.meshPath = "meshes/fascia.vtri";
    fascia.attachTo = "fat";
    fascia.attachDistance = 5e-4;
    fascia.stretchStiffness = 40;
    s.surfaces.push_back(fascia);
    r.surfaces.push_back(fasciaSheet(32, 24, 0.04, 0.03));

    InteractionDesc in;
    InstrumentDesc grasper;
    grasper.name = "grasper";
    grasper.kind = InstrumentDesc::Kind::Grasper;
    grasper.trackPath = "tools/grasper.track";
    grasper.radius = 0.0015;
    grasper.trackText = std::string(kHeader) +
                        "0.00 0.010 0.008 0.030 0 0 -1 1 0\n"
                        "0.20 0.010 0.008 0.0105 0 0 -1 1 0\n"
                        "0.30 0.010 0.008 0.0100 0 0 -1 0 0\n"
                        "0.60 0.010 0.008 0.0180 0 0 -1 0 0\n";
    InstrumentDesc hook;
    hook.name = "hook";
    hook.kind = InstrumentDesc::Kind::EnergyHook;
    hook.trackPath = "tools/hook.track";
    hook.radius = 0.0012;
    hook.jawLength = 0.01;
    hook.trackText = std::string(kHeader) +
                     "0.00 0.008 0.020 0.0102 0 0 -1 1 1\n"
                     "0.50 0.032 0.020 0.0102 0 0 -1 1 1\n"
                     "0.55 0.032 0.020 0.0300 0 0 -1 1 0\n";
    InstrumentDesc clip;
    clip.name = "clipper";
    clip.kind = InstrumentDesc::Kind::ClipApplier;
    clip.trackPath = "tools/clipper.track";
    clip.target = "vessel";
    clip.jawLength = 0.008;
    clip.trackText = std::string(kHeader) +
                     "0.00 0.020 0.020 0.005 0 0 -1 1 0\n"
                     "0.10 0.020 0.020 0.005 0 0 -1 0 1\n";
    in.instruments = {grasper, hook, clip};
    in.tissues.push_back({"fascia", 160, 0.4, Vec3(0.1, 0.3, 1.0)});
    s.interaction = in;
    return r;
}

std::unique_ptr<World> assemble(Rig r) {
    const std::vector<std::string> features = requiredFeatures(r.scene);
    return World::assemble(r.scene, std::move(r.meshes), std::move(r.surfaces), features, "test");
}

} // namespace

TEST(Interaction, SectionRoundTripsAndFeaturesFollowTheInstruments) {
    Rig r = makeRig();
    const std::string text = formatInteractionSection(*r.scene.interaction);
    const InteractionDesc back = parseInteractionSection(text, "scene.json");
    ASSERT_EQ(back.instruments.size(), 3u);
    EXPECT_EQ(back.instruments[1].kind, InstrumentDesc::Kind::EnergyHook);
    EXPECT_DOUBLE_EQ(back.instruments[1].temperatureC, 170);
    EXPECT_EQ(back.instruments[2].target, "vessel");
    EXPECT_EQ(back.tissues.at(0).layer, "fascia");
    EXPECT_EQ(formatInteractionSection(back), text);
    const auto f = requiredFeatures(r.scene);
    for (const char* want : {"clip", "collision", "dissection"})
        EXPECT_NE(std::find(f.begin(), f.end(), want), f.end()) << want;
    r.scene.interaction->instruments.pop_back(); // no clip applier → no clip subsystem
    const auto g = requiredFeatures(r.scene);
    EXPECT_EQ(std::find(g.begin(), g.end(), "clip"), g.end());
}

TEST(Interaction, RejectsBadSectionsNamingTheField) {
    const std::string ok = R"({"instruments": [{"name": "g", "kind": "grasper", "track": "t.track"}]})";
    EXPECT_EQ(sectionError(ok), "accepted");
    EXPECT_THAT(sectionError("{"), HasSubstr("interaction: not valid JSON"));
    EXPECT_THAT(sectionError(R"({"instruments": []})"), HasSubstr("interaction.instruments: must be an array of 1 to 8"));
    EXPECT_THAT(sectionError(R"({"instruments": [{"name": "g", "kind": "saw", "track": "t"}]})"),
                HasSubstr("instruments[0].kind: 'saw' is not an instrument"));
    EXPECT_THAT(sectionError(R"({"instruments": [{"name": "g", "kind": "grasper", "track": "/etc/t"}]})"),
                HasSubstr("instruments[0].track: must be a relative path"));
    EXPECT_THAT(sectionError(R"({"instruments": [{"name": "g", "kind": "grasper", "track": "t", "temperature_c": 90}]})"),
                HasSubstr("instruments[0].temperature_c: only an energy_hook"));
    EXPECT_THAT(sectionError(R"({"instruments": [{"name": "h", "kind": "energy_hook", "track": "t"}]})"),
                HasSubstr("interaction.tissues: an energy_hook needs at least one tissue"));
    EXPECT_THAT(sectionError(R"({"instruments": [{"name": "c", "kind": "clip_applier", "track": "t"}]})"),
                HasSubstr("instruments[0].target: required field is missing"));
    EXPECT_THAT(sectionError(R"({"collision": {"delta": -1}, "instruments": [{"name": "g", "kind": "grasper", "track": "t"}]})"),
                HasSubstr("collision.delta: must be a number in [0, 10]"));
    EXPECT_THAT(sectionError(R"({"collision": {"method": "sdf"}, "instruments": [{"name": "g", "kind": "grasper", "track": "t"}]})"),
                HasSubstr("collision.method: 'sdf' is not a method"));
    EXPECT_THAT(sectionError(R"({"instruments": [{"name": "g", "kind": "grasper", "track": "t"},
                                                 {"name": "g", "kind": "grasper", "track": "u"}]})"),
                HasSubstr("instruments[1].name: 'g' is used twice"));
    EXPECT_THAT(sectionError(R"({"instruments": [{"name": "g", "kind": "grasper", "track": "t"}],
                                 "tissues": [{"layer": "fascia", "shrink": [0.1, 0, 1]}]})"),
                HasSubstr("tissues[0].shrink: must be an array of 3 ratios in (0, 1]"));
    // Scene level: names must exist, XPBD only.
    const std::string scene = R"({"solver": {"type": "xpbd"}, "bodies": [{"name": "fat", "mesh": "m.vtet",
        "material": {"model": "stable_neo_hookean", "youngs_modulus": 3000, "poisson_ratio": 0.45, "density": 950}}],
        "interaction": {"instruments": [{"name": "c", "kind": "clip_applier", "track": "t", "target": "vessel"}]}})";
    try {
        parseScene(scene, "scene.json");
        FAIL() << "accepted a clip target that is not a body";
    } catch (const viscera::InputError& e) {
        EXPECT_THAT(e.what(), HasSubstr("interaction.instruments[0].target: 'vessel' is not a body of the scene"));
    }
}

TEST(Interaction, WorldGraspsCutsAndClipsAndIsRepeatable) {
    auto run = [](std::vector<Vec3>* fasciaOut) {
        std::unique_ptr<World> w = assemble(makeRig());
        const size_t fasciaVertices = w->surfacePositions(0).size();
        double maxLift = 0;
        for (int f = 0; f < 36; ++f) {
            const FrameRecord rec = w->step();
            EXPECT_TRUE(rec.finite) << "frame " << f;
            for (const Vec3& p : w->surfacePositions(0)) {
                EXPECT_TRUE(p.allFinite());
                maxLift = std::max(maxLift, p.z() - kTop);
            }
        }
        EXPECT_TRUE(w->invariants().allFinite);
        const InteractionSummary& s = w->interaction()->summary();
        EXPECT_EQ(w->surfacePositions(0).size(), fasciaVertices) << "dissection adds no vertex";
        EXPECT_EQ(s.fasciaVertices, fasciaVertices);
        EXPECT_GT(s.fasciaEdgesCut, 10) << "the hook cut the fascia along its 2.4 cm path";
        EXPECT_GT(s.fasciaTrianglesCut, 0);
        EXPECT_EQ(s.grasps, 1);
        EXPECT_GT(s.instruments.at(0).grasped, 0) << "the grasper holds fascia vertices";
        EXPECT_GT(maxLift, 0.004) << "the grasped fascia was lifted with the jaws";
        EXPECT_GT(s.maxContacts, 0);
        EXPECT_EQ(s.clips.size(), 1u);
        if (!s.clips.empty()) {
            EXPECT_GT(s.clips[0].regionVertices + s.clips[0].auxiliaryNodes, 10);
            EXPECT_LT(s.clips[0].maxContactDrift, 5e-4) << "the clip follows the vessel";
        }
        std::printf("fascia edges cut %d (triangles %d), grasped %d vertices, lift %.2f mm, max contacts %d, "
                    "clip drift %.4f mm (region %d + %d auxiliary)\n",
                    s.fasciaEdgesCut, s.fasciaTrianglesCut, s.instruments.at(0).grasped, maxLift * 1e3, s.maxContacts,
                    s.clips.empty() ? -1.0 : s.clips[0].maxContactDrift * 1e3, s.clips.empty() ? 0 : s.clips[0].regionVertices,
                    s.clips.empty() ? 0 : s.clips[0].auxiliaryNodes);
        std::vector<uint8_t> mask;
        w->interaction()->surfaceFaceMaskInto(0, mask);
        EXPECT_EQ(mask.size(), w->surfaceMesh(0).triangleCount());
        EXPECT_EQ(static_cast<int>(std::count(mask.begin(), mask.end(), 0)), s.fasciaTrianglesCut);
        *fasciaOut = w->surfacePositions(0);
    };
    std::vector<Vec3> a, b;
    run(&a);
    run(&b);
    ASSERT_EQ(a.size(), b.size());
    for (size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a[i], b[i]) << "repeat runs are bit-identical (vertex " << i << ")";
}
