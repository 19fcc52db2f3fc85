// Geometric clip [A §5.4]: µs per clip update (MLS transform eq. 5.15, exp-map rotation eq.
// 5.17–5.18, rigid clip pose eq. 5.16) and per visual flattening pass (eq. 5.19), for several
// region sizes. The vessel alternates between two deformed states so that the rotation update
// does real work every call. Run: ./build/bench/bench_clip --benchmark_min_time=0.2
#include "sim/clip/clip_flattening.hpp"
#include "sim/mesh/generators.hpp"

#include <benchmark/benchmark.h>

#include <Eigen/Geometry>

#include <cmath>
#include <memory>
#include <vector>

using namespace viscera::sim;

namespace {

struct Scene {
    std::unique_ptr<TetMesh> mesh;
    std::unique_ptr<ClipAttachment> clip;
    std::unique_ptr<ClipFlattening> flat;
    std::vector<Vec3> xa, xb, render, out;
};

/// Tube of radius 2–3 mm, 6 cm, `rings` × 32 slices × 2 layers; clip across the middle with the
/// given half depth along the vessel (mm); auxiliary level 2.
Scene makeScene(int rings, double halfDepthMm) {
    Scene s;
    HollowTubeSpec spec;
    spec.end = Vec3(0, 0, 0.06);
    spec.innerRadius = 0.002;
    spec.outerRadius = 0.003;
    spec.slices = 32;
    spec.layers = 2;
    spec.rings = rings;
    s.mesh = makeHollowTubeTetMesh(spec);
    const Vec3 c(0, 0, 0.03);
    ClipDesc d;
    d.bounds = ClipBounds::box(c, Mat3::Identity(), Vec3(0.004, 0.0035, halfDepthMm * 1e-3));
    d.jawNormal = Vec3::UnitY();
    for (int i = 0; i < 16; ++i)
        d.vertices.push_back(c + Vec3(i % 2 ? 0.004 : -0.004, i % 4 < 2 ? 0.003 : -0.003, i % 8 < 4 ? 0.001 : -0.001));
    for (int i = 0; i < 64; ++i)
        d.contactPoints.push_back(c + Vec3(-0.004 + i * 1.25e-4, 0.003, 0));
    s.clip = ClipAttachment::apply(*s.mesh, s.mesh->positions(), d);
    // Two bent states (bending about x through the clip, ±) with a small shift.
    auto bent = [&](double k) {
        std::vector<Vec3> x = s.mesh->positions();
        for (Vec3& p : x) {
            const double a = k * (p.z() - 0.03);
            p = Eigen::AngleAxisd(a, Vec3::UnitX()).toRotationMatrix() * (p - c) + c + Vec3(0, 1e-3 * k, 0);
        }
        return x;
    };
    s.xa = bent(5.0);
    s.xb = bent(-5.0);
    s.mesh->requireLevel(3);
    for (int32_t v : s.mesh->boundaryVertexMap())
        s.render.push_back(s.mesh->positions()[v]);
    std::vector<Vec3> skeleton;
    for (int i = 0; i <= 12; ++i)
        skeleton.emplace_back(0, 0, 0.005 * i);
    s.flat = ClipFlattening::create(*s.clip, s.render, skeleton);
    return s;
}

void setCounters(benchmark::State& state, const Scene& s) {
    state.counters["region_vertices"] = static_cast<double>(s.clip->regionVertices().size());
    state.counters["aux_nodes"] = static_cast<double>(s.clip->auxiliaryNodes().size());
    state.counters["flatten_candidates"] = static_cast<double>(s.flat->candidates().size());
    state.counters["region_nodes"] =
        static_cast<double>(s.clip->regionVertices().size() + s.clip->auxiliaryNodes().size());
}

void BM_ClipUpdate(benchmark::State& state) {
    Scene s = makeScene(static_cast<int>(state.range(0)), static_cast<double>(state.range(1)));
    bool flip = false;
    for (auto _ : state) {
        flip = !flip;
        benchmark::DoNotOptimize(s.clip->update(flip ? s.xa : s.xb));
        benchmark::ClobberMemory();
    }
    setCounters(state, s);
}

void BM_ClipUpdateAndFlatten(benchmark::State& state) {
    Scene s = makeScene(static_cast<int>(state.range(0)), static_cast<double>(state.range(1)));
    bool flip = false;
    for (auto _ : state) {
        flip = !flip;
        s.clip->update(flip ? s.xa : s.xb);
        s.flat->flattenInto(*s.clip, s.render, s.out);
        benchmark::DoNotOptimize(s.out.data());
        benchmark::ClobberMemory();
    }
    setCounters(state, s);
}

// (rings along 6 cm, clip half depth in mm)
#define CLIP_ARGS Args({16, 1})->Args({16, 3})->Args({48, 3})->Args({96, 6})->Unit(benchmark::kMicrosecond)
BENCHMARK(BM_ClipUpdate)->CLIP_ARGS;
BENCHMARK(BM_ClipUpdateAndFlatten)->CLIP_ARGS;

} // namespace

BENCHMARK_MAIN();
