// Physics time per step of the anastomosis run [B ch. 4], single thread: mean, p50, p99 and max for
// the running suture with 20 and with 52 punctures (5 and 13 stitches), needle driving and thread
// pull, and what the slowest steps did (refactorization, puncture, new contacts, substitutions).
// Run: OPENBLAS_NUM_THREADS=1 taskset -c 0 ./build/bench/bench_suture [5|13] [--refactor MODE] [--pace FPS]
//        [--slowest N]
//   MODE: synchronous | background (default background; see FemSettings::refactorMode). With
//   --pace 60 the steps run as in the player, one per 1/60 s frame on the same core, and the
//   background factorization (lowest priority) takes the idle rest of the frames; without it the
//   steps run back to back and the worker competes with them.
// Columns: physics time of SutureSimulation::step() per frame (ms), final closure figures (mm).
#include "sim/suture/anastomosis.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

using namespace viscera::sim;

namespace {

struct StepRecord {
    int frame = 0;
    double ms = 0;
    SutureStepStats st;
};

bool parseMode(const char* text, RefactorMode& mode) {
    const std::string t = text;
    if (t == "synchronous")
        mode = RefactorMode::Synchronous;
    else if (t == "background")
        mode = RefactorMode::Background;
    else
        return false;
    return true;
}

const char* modeName(RefactorMode m) {
    switch (m) {
    case RefactorMode::Synchronous:
        return "synchronous";
    case RefactorMode::Background:
        return "background";
    }
    return "?";
}

} // namespace

int main(int argc, char** argv) {
    int only = 0, slowest = 0;
    double pace = 0; // frames per second; 0 = steps back to back
    RefactorMode mode = RefactorMode::Background;
    for (int i = 1; i < argc; ++i) {
        if (!std::strcmp(argv[i], "--refactor") && i + 1 < argc) {
            if (!parseMode(argv[++i], mode)) {
                std::fprintf(stderr, "bench_suture: --refactor %s: expected synchronous or background\n", argv[i]);
                return 2;
            }
        } else if (!std::strcmp(argv[i], "--pace") && i + 1 < argc) {
            pace = std::atof(argv[++i]);
        } else if (!std::strcmp(argv[i], "--slowest") && i + 1 < argc) {
            slowest = std::atoi(argv[++i]);
        } else {
            only = std::atoi(argv[i]);
        }
    }
    std::printf("refactor mode: %s, %s\n", modeName(mode), pace > 0 ? "paced" : "steps back to back");
    std::printf("%-10s %-8s %-8s %-10s %-10s %-10s %-10s %-10s %-12s %-8s\n", "punctures", "stitches", "frames",
                "mean_ms", "p50_ms", "p99_ms", "max_ms", "gap_mm", "penetr_mm", "factors");
    for (int stitches : {5, 13}) {
        if (only && only != stitches) continue;
        AnastomosisSpec spec;
        spec.stitches = stitches;
        if (stitches > 8) spec.pullPerSegment = 0.0021; // closer stitches: less pull closes the gap
        SutureSettings s;
        s.needle.punctureForce = 0.008;
        s.fem.youngsModulus = 60e3;
        s.fem.refactorMode = mode;
        s.fem.refactorLatencySteps = 30; // the worker shares the core: give it 30 steps
        AnastomosisRun run = makeAnastomosisRun(spec, s);
        SutureSimulation* sim = run.sim.get();
        const std::vector<NeedleFrame>& frames = run.frames;
        ClosureGauge gauge(sim->mesh(), run.narrowOffset);
        std::vector<StepRecord> rec;
        int punctures = 0;
        auto frameStart = std::chrono::steady_clock::now();
        const auto period = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
            std::chrono::duration<double>(pace > 0 ? 1.0 / pace : 0.0));
        for (size_t f = 0; f < frames.size(); ++f) {
            if (pace > 0) { // as the player: one step per frame, the rest of the frame idle
                std::this_thread::sleep_until(frameStart);
                frameStart += period;
            }
            const auto t0 = std::chrono::steady_clock::now();
            StepRecord r;
            r.st = sim->step(frames[f]);
            r.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
            r.frame = static_cast<int>(f);
            punctures = r.st.punctures;
            rec.push_back(std::move(r));
        }
        const ClosureMetrics cm = gauge.measure(sim->positions());
        std::vector<double> sorted;
        double sum = 0;
        for (const StepRecord& r : rec) {
            sorted.push_back(r.ms);
            sum += r.ms;
        }
        std::sort(sorted.begin(), sorted.end());
        auto pct = [&](double p) {
            return sorted[std::min(sorted.size() - 1, static_cast<size_t>(p * sorted.size()))];
        };
        std::printf("%-10d %-8d %-8zu %-10.3f %-10.3f %-10.3f %-10.3f %-10.3f %-12.3f %-8d\n", punctures, stitches,
                    frames.size(), sum / rec.size(), pct(0.5), pct(0.99), sorted.back(), cm.maxGap * 1e3,
                    cm.maxPenetration * 1e3, sim->fem().factorizations());
        if (slowest > 0) {
            std::vector<StepRecord> bySlow = rec;
            std::sort(bySlow.begin(), bySlow.end(), [](const auto& a, const auto& b) { return a.ms > b.ms; });
            std::printf("  slowest steps: frame ms refactored punctured new_contacts contacts solves rows "
                        "new_cached substitutions active_set_iterations\n");
            for (int i = 0; i < std::min<int>(slowest, static_cast<int>(bySlow.size())); ++i) {
                const StepRecord& r = bySlow[i];
                std::printf("  %6d %9.3f %d %d %4d %4d %3d %4d %4d %5d %4d\n", r.frame, r.ms, r.st.refactored,
                            r.st.punctured, r.st.newContacts, r.st.contacts, r.st.solves, r.st.activeRows,
                            r.st.newCachedNodes, r.st.substitutions, r.st.activeSetIterations);
            }
        }
    }
    return 0;
}
