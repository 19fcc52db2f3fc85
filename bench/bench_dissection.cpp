// Energized dissection [A §5.3.4]: ms per frame of the dissection update alone and of the full
// frame (dissection + XPBD step) for the 6,050-triangle fascia and the 30,000-tet fat block, with
// the tool dragged through the tissue at 20 mm/s (fascia: 170 °C, fat: 90 °C). The thesis reports
// 103 fps (fascia) and 15 fps (fat + fascia) on a GPU.
// Run: ./build/bench/bench_dissection [frames]
#include "../tests/sim/dissection/dissection_test_support.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

using namespace viscera::sim;
using namespace viscera::sim::dissection_test;
using Clock = std::chrono::steady_clock;

namespace {

struct Figures {
    double dissectionMs = 0, frameMs = 0, worstFrameMs = 0;
    size_t cutEdges = 0, cutPrims = 0;
};

template <class StepFn> Figures measure(int frames, const StepFn& frame) {
    Figures f;
    std::vector<double> d, t;
    for (int i = 0; i < frames; ++i) {
        const auto t0 = Clock::now();
        const DissectionLayerStats st = frame(i, true);
        const auto t1 = Clock::now();
        frame(i, false);
        const auto t2 = Clock::now();
        d.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
        t.push_back(std::chrono::duration<double, std::milli>(t2 - t0).count());
        f.cutEdges = st.totalEdgesCut;
        f.cutPrims = st.totalPrimitivesCut;
    }
    for (size_t i = 0; i < d.size(); ++i) {
        f.dissectionMs += d[i] / d.size();
        f.frameMs += t[i] / t.size();
        f.worstFrameMs = std::max(f.worstFrameMs, t[i]);
    }
    return f;
}

void print(const char* name, size_t elems, const char* kind, const Figures& f, int threads) {
    std::printf("%-7s %6zu %-9s threads %d: dissection %.3f ms/frame, full frame %.3f ms (%.1f "
                "fps), worst %.3f ms; "
                "cut %zu edges, %zu %s\n",
                name, elems, kind, threads, f.dissectionMs, f.frameMs, 1000.0 / f.frameMs, f.worstFrameMs, f.cutEdges,
                f.cutPrims, kind);
}

} // namespace

int main(int argc, char** argv) {
    const int frames = argc > 1 ? std::max(1, std::atoi(argv[1])) : 120;
    const double dt = 1.0 / 60.0;
    for (int threads : {1, defaultXpbdThreads()}) {
        {
            FasciaScene s = makeFasciaScene(threads);
            DissectionLayerStats last;
            const Figures f = measure(frames, [&](int i, bool dissect) {
                if (dissect) {
                    const Vec3 c(-0.02 + 0.02 * dt * i, 0.0031, 0.0);
                    last = s.dissection->update({c, 1e-3, 170.0, true}, dt).fascia;
                } else {
                    s.system->step();
                }
                return last;
            });
            print("fascia", s.sheet.triangleCount(), "triangles", f, threads);
        }
        {
            FatScene s = makeFatScene(threads);
            DissectionLayerStats last;
            const Figures f = measure(frames, [&](int i, bool dissect) {
                if (dissect) {
                    const Vec3 c(-0.02 + 0.02 * dt * i, 0.0, -0.004);
                    last = s.dissection->update({c, 1.5e-3, 90.0, true}, dt).fat;
                } else {
                    s.system->step();
                }
                return last;
            });
            print("fat", s.mesh->tetCount(), "tets", f, threads);
        }
    }
    return 0;
}
