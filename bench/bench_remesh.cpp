// Voxel remesh of the kidney-like sample (bake/sample_anatomy.hpp) at two voxel counts along its
// longest axis, with its UVs cut in and transferred (seam cutting) and without: time per stage and
// the figures of the result as counters (triangles, intersecting pairs, distance to the source in
// mm, volume change from the isosurface in %, seam edges, time of the UV stage).
// Run: ./build/bench/bench_remesh
#include "bake/remesh.hpp"
#include "bake/sample_anatomy.hpp"

#include <benchmark/benchmark.h>

using namespace viscera;

static void BM_RemeshKidney(benchmark::State& state) {
    const std::vector<bake::RemeshPart> parts = bake::kidneyAnatomy();
    bake::RemeshParams params;
    params.voxelCount = int(state.range(0));
    params.transferUv = state.range(1) != 0;
    bake::RemeshReport q;
    for (auto _ : state) {
        const bake::RemeshResult r = bake::voxelRemesh(parts, params);
        q = r.report;
        benchmark::DoNotOptimize(r.mesh.triangleCount());
    }
    state.counters["voxel_mm"] = q.voxelSize * 1e3;
    state.counters["active_voxels"] = double(q.activeVoxels);
    state.counters["triangles"] = double(q.triangles);
    state.counters["self_intersections"] = double(q.selfIntersections);
    state.counters["dist_mean_mm"] = q.distanceMeanMm;
    state.counters["dist_max_mm"] = q.distanceMaxMm;
    state.counters["vol_change_pct"] = 100.0 * q.volumeChangeFromIso;
    state.counters["levelset_s"] = q.levelSetSeconds;
    state.counters["remesh_s"] = q.remeshSeconds;
    state.counters["check_s"] = q.checkSeconds;
    state.counters["seam_edges"] = double(q.seamEdges);
    state.counters["uv_s"] = q.uvSeconds;
}
BENCHMARK(BM_RemeshKidney)
    ->ArgsProduct({{64, 128}, {0, 1}})
    ->ArgNames({"voxels", "uv"})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3);

BENCHMARK_MAIN();
