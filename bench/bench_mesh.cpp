// CHF adjacency: build time per level and query throughput on structured blocks.
#include "sim/mesh/generators.hpp"
#include "sim/mesh/tet_mesh.hpp"

#include <benchmark/benchmark.h>

using namespace viscera::sim;

namespace {
std::unique_ptr<TetMesh> block(int n) {
    return makeBoxTetMesh({Vec3::Zero(), Vec3(0.1, 0.1, 0.05), {n, n, n / 2}});
}
} // namespace

static void BM_BuildLevels(benchmark::State& state) {
    auto base = block(static_cast<int>(state.range(0)));
    for (auto _ : state) {
        auto m = TetMesh::fromArrays(base->positions(), base->tets());
        m->requireLevel(3);
        benchmark::DoNotOptimize(m->edgeCount());
        state.counters["adjacency_bytes_per_tet"] = double(m->adjacencyBytes()) / double(m->tetCount());
    }
    state.counters["tets"] = double(base->tetCount());
    state.SetItemsProcessed(state.iterations() * int64_t(base->tetCount()));
}
BENCHMARK(BM_BuildLevels)->Arg(20)->Arg(40)->Unit(benchmark::kMillisecond);

static void BM_CellsOfVertex(benchmark::State& state) {
    auto m = block(40);
    m->requireLevel(2);
    std::vector<int32_t> out;
    int32_t v = 0;
    const auto n = static_cast<int32_t>(m->vertexCount());
    for (auto _ : state) {
        m->cellsOfVertexInto(v, out);
        benchmark::DoNotOptimize(out.data());
        v = (v + 7919) % n;
    }
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_CellsOfVertex);

static void BM_LinkFacetsOfEdge(benchmark::State& state) {
    auto m = block(40);
    m->requireLevel(2);
    std::vector<int32_t> out;
    int32_t e = 0;
    const auto n = static_cast<int32_t>(m->edgeCount());
    for (auto _ : state) {
        m->linkFacetsOfEdgeInto(m->edgeHalfEdge(e), out);
        benchmark::DoNotOptimize(out.data());
        e = (e + 7919) % n;
    }
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_LinkFacetsOfEdge);
