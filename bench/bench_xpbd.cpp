// XPBD frame cost on a block fixed at one end: ms per frame and ns per tet-iteration.
//
// BM_XpbdFrame/<cells>/<threads>/<simd>: a box of 2n × n × n/2 hex cells (6 tets each), 20
// substeps × 1 iteration per 1/60 s frame, stable Neo-Hookean, gravity on.
// BM_XpbdFrame30k/<threads>/<simd>: the 30,000-tet block of the performance target
// (25 × 20 × 10 cells, 25 × 20 × 10 cm).
// BM_XpbdFramePrimal/<threads>: BM_XpbdFrame30k with the primal correction (AVX2 sweeps).
#include "sim/mesh/generators.hpp"
#include "sim/xpbd/xpbd_solver.hpp"

#include <benchmark/benchmark.h>

using namespace viscera::sim;

namespace {

void runFrames(benchmark::State& state, const BoxSpec& box, int threads, bool simd, bool primal = false) {
    auto mesh = makeBoxTetMesh(box);
    std::vector<int32_t> fixed;
    for (int32_t v = 0; v < static_cast<int32_t>(mesh->vertexCount()); ++v)
        if (mesh->positions()[v].x() < box.origin.x() + 1e-9) fixed.push_back(v);
    XpbdSettings s;
    s.substeps = 20;
    s.iterations = 1;
    s.threads = threads;
    s.simd = simd;
    s.primalCorrection = primal;
    Material mat;
    mat.youngsModulus = 20000;
    auto solver = XpbdSolver::create(*mesh, mat, fixed, s);
    if (simd && !solver->usesSimd()) {
        state.SkipWithError("no AVX2/FMA on this CPU");
        return;
    }
    for (auto _ : state)
        benchmark::DoNotOptimize(solver->step().maxDisplacement);
    const double tetIters = double(mesh->tetCount()) * s.substeps * s.iterations;
    state.counters["tets"] = double(mesh->tetCount());
    state.counters["colours"] = solver->colourCount();
    // Seconds per tet-iteration (printed with an SI prefix, e.g. "14n" = 14 ns).
    state.counters["time_per_tet_iteration"] =
        benchmark::Counter(tetIters, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
    state.SetItemsProcessed(state.iterations() * int64_t(tetIters));
}

void BM_XpbdFrame(benchmark::State& state) {
    const int n = static_cast<int>(state.range(0));
    runFrames(state, {Vec3::Zero(), Vec3(0.2, 0.1, 0.05), {2 * n, n, n / 2}}, static_cast<int>(state.range(1)),
              state.range(2) != 0);
}

void BM_XpbdFrame30k(benchmark::State& state) {
    runFrames(state, {Vec3::Zero(), Vec3(0.25, 0.2, 0.1), {25, 20, 10}}, static_cast<int>(state.range(0)),
              state.range(1) != 0);
}

/// The same frame with the primal correction after every iteration (XpbdSettings::
/// primalCorrection): the cost of converging to the implicit step instead of levelling off.
void BM_XpbdFramePrimal(benchmark::State& state) {
    runFrames(state, {Vec3::Zero(), Vec3(0.25, 0.2, 0.1), {25, 20, 10}}, static_cast<int>(state.range(0)), true, true);
}

} // namespace

BENCHMARK(BM_XpbdFramePrimal)->ArgNames({"threads"})->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_XpbdFrame)
    ->ArgNames({"cells", "threads", "simd"})
    ->Args({10, 1, 1})
    ->Args({20, 1, 1})
    ->Args({20, 2, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_XpbdFrame30k)
    ->ArgNames({"threads", "simd"})
    ->Args({1, 0})
    ->Args({2, 0})
    ->Args({1, 1})
    ->Args({2, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
