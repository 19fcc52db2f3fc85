// XPBD frame cost on a block fixed at one end: ms per frame and ns per tet-iteration.
#include "sim/mesh/generators.hpp"
#include "sim/xpbd/xpbd_solver.hpp"

#include <benchmark/benchmark.h>

using namespace viscera::sim;

static void BM_XpbdFrame(benchmark::State& state) {
    const int n = static_cast<int>(state.range(0));
    auto mesh = makeBoxTetMesh({Vec3::Zero(), Vec3(0.2, 0.1, 0.05), {2 * n, n, n / 2}});
    std::vector<int32_t> fixed;
    for (int32_t v = 0; v < static_cast<int32_t>(mesh->vertexCount()); ++v)
        if (mesh->positions()[v].x() < 1e-9) fixed.push_back(v);
    XpbdSettings s;
    s.substeps = 20;
    s.iterations = 1;
    Material mat;
    mat.youngsModulus = 20000;
    auto solver = XpbdSolver::create(*mesh, mat, fixed, s);
    for (auto _ : state) benchmark::DoNotOptimize(solver->step().maxDisplacement);
    const double tetIters = double(mesh->tetCount()) * s.substeps * s.iterations;
    state.counters["tets"] = double(mesh->tetCount());
    // Seconds per tet-iteration (printed with an SI prefix, e.g. "144n" = 144 ns).
    state.counters["time_per_tet_iteration"] =
        benchmark::Counter(tetIters, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
    state.SetItemsProcessed(state.iterations() * int64_t(tetIters));
}
BENCHMARK(BM_XpbdFrame)->Arg(10)->Arg(20)->Unit(benchmark::kMillisecond);
