// Physics time per step of the anastomosis run [B ch. 4], single thread: mean and p99 for the
// running suture with 20 and with 50 punctures (5 and 13 stitches), needle driving and thread pull.
// Run: OPENBLAS_NUM_THREADS=1 taskset -c 0 ./build/bench/bench_suture [5|13]
// Columns: physics time of SutureSimulation::step() per frame (ms), final closure figures (mm).
#include "sim/suture/anastomosis.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

using namespace viscera::sim;

int main(int argc, char** argv) {
    const int only = argc > 1 ? std::atoi(argv[1]) : 0;
    std::printf("%-10s %-8s %-8s %-10s %-10s %-10s %-10s %-10s %-12s\n", "punctures", "stitches", "frames", "mean_ms",
                "p50_ms", "p99_ms", "max_ms", "gap_mm", "penetr_mm");
    for (int stitches : {5, 13}) {
        if (only && only != stitches) continue;
        AnastomosisSpec spec;
        spec.stitches = stitches;
        if (stitches > 8) spec.pullPerSegment = 0.0021; // closer stitches: less pull closes the gap
        SutureSettings s;
        s.needle.punctureForce = 0.008;
        s.fem.youngsModulus = 60e3;
        // One core: a background refactorization would share it, so it runs in the step (the same
        // settings as the SutureStability acceptance test).
        s.fem.refactorMode = RefactorMode::Synchronous;
        AnastomosisRun run = makeAnastomosisRun(spec, s);
        SutureSimulation* sim = run.sim.get();
        const std::vector<NeedleFrame>& frames = run.frames;
        ClosureGauge gauge(sim->mesh(), run.narrowOffset);
        std::vector<double> ms;
        int punctures = 0;
        for (const NeedleFrame& f : frames) {
            const auto t0 = std::chrono::steady_clock::now();
            const SutureStepStats st = sim->step(f);
            ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
            punctures = st.punctures;
        }
        const ClosureMetrics cm = gauge.measure(sim->positions());
        std::vector<double> sorted = ms;
        std::sort(sorted.begin(), sorted.end());
        double sum = 0;
        for (double x : ms)
            sum += x;
        auto pct = [&](double p) {
            return sorted[std::min(sorted.size() - 1, static_cast<size_t>(p * sorted.size()))];
        };
        std::printf("%-10d %-8d %-8zu %-10.3f %-10.3f %-10.3f %-10.3f %-10.3f %-12.3f\n", punctures, stitches,
                    frames.size(), sum / ms.size(), pct(0.5), pct(0.99), sorted.back(), cm.maxGap * 1e3,
                    cm.maxPenetration * 1e3);
    }
    return 0;
}
