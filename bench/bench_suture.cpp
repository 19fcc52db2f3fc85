// Physics time per step of the anastomosis run [B ch. 4], single thread: mean, p50, p99 and max for
// the running suture with 20 and with 52 punctures (5 and 13 stitches), needle driving and thread
// pull, and what the slowest steps did (refactorization, puncture, new contacts, substitutions).
// Run: OPENBLAS_NUM_THREADS=1 taskset -c 0 ./build/bench/bench_suture [5|13] [--refactor MODE] [--pace FPS]
//        [--slowest N] [--prefetch NODES_PER_SOLVE] [--lookahead STEPS] [--latency SOLVES]
//        [--carry NODES_PER_SOLVE] [--hold FRAMES]
//   --hold appends FRAMES copies of the last frame (the closed suture held at full pull, as the player
//   does past the trajectory's end; up to 256 contacts); --carry sets FemSettings::refactorNodesPerSolve.
//   MODE: synchronous | background (default background; see FemSettings::refactorMode). With
//   --pace 60 the steps run as in the player, one per 1/60 s frame on the same core, and the
//   background factorization takes the idle rest of the frames; without it the steps run back to
//   back and the worker shares the core with them (so the default latency is 120 solves).
// Columns: physics time of SutureSimulation::step() per frame (ms; wall clock, and the stepping thread's CPU
// time), final closure figures (mm), factorizations, steps that waited for the background worker.
#include "sim/suture/anastomosis.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <string>
#include <thread>
#include <vector>

using namespace viscera::sim;

namespace {

/// CPU time of the calling thread, ms: unlike wall time, not inflated when other processes of a
/// shared machine take the core (the background factorization's thread is not counted either; a
/// step that waits for it shows in wall time only).
double threadCpuMs() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return 1e3 * static_cast<double>(ts.tv_sec) + 1e-6 * static_cast<double>(ts.tv_nsec);
}

struct Stats {
    double mean = 0, p50 = 0, p99 = 0, max = 0;
};
Stats stats(std::vector<double> v) {
    Stats s;
    std::sort(v.begin(), v.end());
    for (double x : v)
        s.mean += x / static_cast<double>(v.size());
    auto pct = [&](double p) { return v[std::min(v.size() - 1, static_cast<size_t>(p * v.size()))]; };
    s.p50 = pct(0.5);
    s.p99 = pct(0.99);
    s.max = v.back();
    return s;
}

struct StepRecord {
    int frame = 0;
    double ms = 0, cpuMs = 0;
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
    double pace = 0;                   // frames per second; 0 = steps back to back
    int prefetch = -1, lookahead = -1; // FemSettings::prefetchNodesPerSolve, contactLookaheadSteps (-1: default)
    int latency = 120;                 // FemSettings::refactorLatencySteps
    int carry = -1;                    // FemSettings::refactorNodesPerSolve (-1: default)
    int hold = 0;                      // frames of the last pose (full pull) appended: the closed suture held
    RefactorMode mode = RefactorMode::Background;
    for (int i = 1; i < argc; ++i) {
        if (!std::strcmp(argv[i], "--refactor") && i + 1 < argc) {
            if (!parseMode(argv[++i], mode)) {
                std::fprintf(stderr, "bench_suture: --refactor %s: expected synchronous or background\n", argv[i]);
                return 2;
            }
        } else if (!std::strcmp(argv[i], "--prefetch") && i + 1 < argc) {
            prefetch = std::atoi(argv[++i]);
        } else if (!std::strcmp(argv[i], "--lookahead") && i + 1 < argc) {
            lookahead = std::atoi(argv[++i]);
        } else if (!std::strcmp(argv[i], "--latency") && i + 1 < argc) {
            latency = std::max(1, std::atoi(argv[++i]));
        } else if (!std::strcmp(argv[i], "--carry") && i + 1 < argc) {
            carry = std::max(1, std::atoi(argv[++i]));
        } else if (!std::strcmp(argv[i], "--hold") && i + 1 < argc) {
            hold = std::max(0, std::atoi(argv[++i]));
        } else if (!std::strcmp(argv[i], "--pace") && i + 1 < argc) {
            pace = std::atof(argv[++i]);
        } else if (!std::strcmp(argv[i], "--slowest") && i + 1 < argc) {
            slowest = std::atoi(argv[++i]);
        } else {
            only = std::atoi(argv[i]);
        }
    }
    std::printf("refactor mode: %s, %s\n", modeName(mode), pace > 0 ? "paced" : "steps back to back");
    std::printf("%-10s %-8s %-8s %-6s %-10s %-10s %-10s %-10s %-10s %-12s %-8s %-6s\n", "punctures", "stitches",
                "frames", "clock", "mean_ms", "p50_ms", "p99_ms", "max_ms", "gap_mm", "penetr_mm", "factors", "waits");
    for (int stitches : {5, 13}) {
        if (only && only != stitches) continue;
        AnastomosisSpec spec;
        spec.stitches = stitches;
        if (stitches > 8) spec.pullPerSegment = 0.0021; // closer stitches: less pull closes the gap
        SutureSettings s;
        s.needle.punctureForce = 0.008;
        s.fem.youngsModulus = 60e3;
        s.fem.refactorMode = mode;
        s.fem.refactorLatencySteps = latency; // the worker shares the core with the steps
        if (prefetch >= 0) s.fem.prefetchNodesPerSolve = prefetch;
        if (carry > 0) s.fem.refactorNodesPerSolve = carry;
        if (lookahead >= 0) s.contactLookaheadSteps = lookahead;
        AnastomosisRun run = makeAnastomosisRun(spec, s);
        SutureSimulation* sim = run.sim.get();
        std::vector<NeedleFrame>& frames = run.frames;
        frames.insert(frames.end(), static_cast<size_t>(hold), frames.back());
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
            const double c0 = threadCpuMs();
            StepRecord r;
            r.st = sim->step(frames[f]);
            r.cpuMs = threadCpuMs() - c0;
            r.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
            r.frame = static_cast<int>(f);
            punctures = r.st.punctures;
            rec.push_back(std::move(r));
        }
        const ClosureMetrics cm = gauge.measure(sim->positions());
        std::vector<double> wall, cpu;
        int waited = 0;
        for (const StepRecord& r : rec) {
            wall.push_back(r.ms);
            cpu.push_back(r.cpuMs);
            waited += r.st.refactorWaited;
        }
        const Stats w = stats(wall), c = stats(cpu);
        std::printf("%-10d %-8d %-8zu %-6s %-10.3f %-10.3f %-10.3f %-10.3f %-10.3f %-12.3f %-8d %-6d\n", punctures,
                    stitches, frames.size(), "wall", w.mean, w.p50, w.p99, w.max, cm.maxGap * 1e3,
                    cm.maxPenetration * 1e3, sim->fem().factorizations(), waited);
        std::printf("%-10s %-8s %-8s %-6s %-10.3f %-10.3f %-10.3f %-10.3f\n", "", "", "", "cpu", c.mean, c.p50, c.p99,
                    c.max);
        if (slowest > 0) {
            std::vector<StepRecord> bySlow = rec;
            std::sort(bySlow.begin(), bySlow.end(), [](const auto& a, const auto& b) { return a.ms > b.ms; });
            std::printf(
                "  slowest steps (wall): frame ms cpu_ms refactored punctured new_contacts contacts solves rows "
                "new_cached substitutions active_set_iterations\n");
            for (int i = 0; i < std::min<int>(slowest, static_cast<int>(bySlow.size())); ++i) {
                const StepRecord& r = bySlow[i];
                std::printf("  %6d %9.3f %9.3f %d %d %4d %4d %3d %4d %4d %5d %4d\n", r.frame, r.ms, r.cpuMs,
                            r.st.refactored, r.st.punctured, r.st.newContacts, r.st.contacts, r.st.solves,
                            r.st.activeRows, r.st.newCachedNodes, r.st.substitutions, r.st.activeSetIterations);
            }
        }
    }
    return 0;
}
