#pragma once
// A small layered world for interaction tests: a 4 × 3 × 1 cm fat pad (bottom fixed), a fascia
// sheet on top, a hollow vessel embedded along x, and a grasper, an energy hook and a clip
// applier on short recorded tracks. Shared by the scene and render tests.
#include "sim/mesh/generators.hpp"
#include "sim/scene/scene.hpp"
#include "sim/scene/world.hpp"

#include <memory>
#include <string>
#include <vector>

namespace viscera::sim::test {

inline const char* kHeader = "# viscera instrument track 1\n";

// Fat pad 4 × 3 × 1 cm (bottom fixed), fascia on top, a vessel inside along x at y = 2 cm.
inline constexpr double kTop = 0.01;

inline TriMesh fasciaSheet(int nx, int ny, double sx, double sy) {
    std::vector<Vec3> p;
    for (int j = 0; j <= ny; ++j)
        for (int i = 0; i <= nx; ++i)
            p.emplace_back(sx * i / nx, sy * j / ny, kTop);
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

inline Rig makeRig() {
    Rig r;
    SceneDesc& s = r.scene;
    s.xpbd.substeps = 70;
    s.xpbd.damping = 2.0;
    s.xpbd.gravity = Vec3(0, 0, -9.81);
    // A tet body meshes/<name>.vtet with Young's modulus E (Pa), ν = 0.45 and density ρ.
    auto body = [](const char* name, double E, double rho) {
        BodyDesc b;
        b.name = name;
        b.meshPath = std::string("meshes/") + name + ".vtet";
        b.material.youngsModulus = E;
        b.material.poissonRatio = 0.45;
        b.material.density = rho;
        return b;
    };
    BodyDesc fat = body("fat", 3000, 950);
    BoxSpec box;
    box.size = Vec3(0.04, 0.03, kTop);
    box.cells = {16, 12, 3};
    r.meshes.push_back(makeBoxTetMesh(box));
    for (int32_t v = 0; v < static_cast<int32_t>(r.meshes[0]->vertexCount()); ++v)
        if (r.meshes[0]->positions()[v].z() < 1e-9) fat.fixedNodes.push_back(v);
    s.bodies.push_back(fat);
    BodyDesc vessel = body("vessel", 1200, 1060);
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
    // Tracks: t x y z  dx dy dz  jaw  act, one key per line.
    auto instrument = [](const char* name, InstrumentDesc::Kind kind, const char* file, const char* keys) {
        InstrumentDesc d;
        d.name = name;
        d.kind = kind;
        d.trackPath = std::string("tools/") + file;
        d.trackText = std::string(kHeader) + keys;
        return d;
    };
    InstrumentDesc grasper = instrument("grasper", InstrumentDesc::Kind::Grasper, "grasper.track",
                                        "0.00 0.010 0.008 0.030 0 0 -1 1 0\n"
                                        "0.20 0.010 0.008 0.0105 0 0 -1 1 0\n"
                                        "0.30 0.010 0.008 0.0100 0 0 -1 0 0\n"
                                        "0.60 0.010 0.008 0.0180 0 0 -1 0 0\n");
    grasper.radius = 0.0015;
    InstrumentDesc hook = instrument("hook", InstrumentDesc::Kind::EnergyHook, "hook.track",
                                     "0.00 0.008 0.020 0.0102 0 0 -1 1 1\n"
                                     "0.50 0.032 0.020 0.0102 0 0 -1 1 1\n"
                                     "0.55 0.032 0.020 0.0300 0 0 -1 1 0\n");
    hook.radius = 0.0012;
    hook.jawLength = 0.01;
    InstrumentDesc clip = instrument("clipper", InstrumentDesc::Kind::ClipApplier, "clipper.track",
                                     "0.00 0.020 0.020 0.005 0 0 -1 1 0\n"
                                     "0.10 0.020 0.020 0.005 0 0 -1 0 1\n");
    clip.target = "vessel";
    clip.jawLength = 0.008;
    in.instruments = {grasper, hook, clip};
    in.tissues.push_back({"fascia", 160, 0.4, Vec3(0.1, 0.3, 1.0)});
    s.interaction = in;
    return r;
}

inline std::unique_ptr<World> assemble(Rig r) {
    const std::vector<std::string> features = requiredFeatures(r.scene);
    return World::assemble(r.scene, std::move(r.meshes), std::move(r.surfaces), features, "test");
}

} // namespace viscera::sim::test
