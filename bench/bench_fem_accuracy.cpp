// Error of the quasi-static corotational FEM against run time, per refactorization and rotation-update
// policy [B §2.2.3]: each policy runs the same suturing scenario (anastomosis, 2 stitches and the
// pull, [B ch. 4]); at every `sample`-th frame the step's result x is compared with the converged
// nonlinear static solution x* of the same step (CorotationalFem::convergedStatic(): Newton on the
// corotational energy with the rotations taken from x itself, under the rows that step enforced).
// Errors: relative energy excess (E(x) − E(x*)) / E(x*) and the largest node distance |x − x*|
// (absolute, and relative to the largest displacement of x* from rest); frames with the tissue at
// rest (E(x*) ≤ 1e-12 J) are skipped.
// Run time: physics time per step (the reference solves are not counted), one thread.
// Run: OPENBLAS_NUM_THREADS=1 taskset -c 0 ./build/bench/bench_fem_accuracy [output-dir] [--sample N]
// Writes <dir>/fem_policies.csv (one row per policy), <dir>/fem_samples.csv (one row per sampled
// frame), <dir>/fem_error_vs_time.png and <dir>/fem_position_error_vs_time.png.
#include "line_plot.hpp"
#include "sim/suture/anastomosis.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

using namespace viscera::sim;
using viscera::bench::PlotSeries;
using viscera::bench::PlotSpec;

namespace {

struct Policy {
    std::string family; ///< plot series
    std::string name;
    bool corotational = true;
    RefactorMode mode = RefactorMode::Synchronous;
    double threshold = 0.25; ///< FemSettings::refactorDisplacement
    int latency = 3;
};

struct Result {
    Policy p;
    double meanMs = 0, p99Ms = 0, maxMs = 0;
    int factorizations = 0, samples = 0, unconverged = 0;
    double meanRelEnergy = 0, maxRelEnergy = 0, meanPosMm = 0, maxPosMm = 0, meanRelPos = 0, maxRelPos = 0;
    struct Sample {
        double relEnergy, posMm, relPos;
    };
    std::map<size_t, Sample> byFrame; ///< measured frames
    // Means over the frames every policy measured (the policies' states differ between frames
    // where the tissue is at rest for some of them): the figures the plots compare.
    int common = 0;
    double commonRelEnergy = 0, commonRelPos = 0;
};

constexpr double kEnergyFloor = 1e-12; ///< J: below, the tissue is at rest and a relative error means nothing

Result run(const Policy& p, int sample, std::ofstream& samples) {
    AnastomosisSpec spec;
    spec.stitches = 2;
    spec.pullFrames = 80;
    SutureSettings s;
    s.needle.punctureForce = 0.008;
    s.fem.youngsModulus = 60e3;
    s.fem.corotational = p.corotational;
    s.fem.refactorMode = p.mode;
    s.fem.refactorDisplacement = p.threshold;
    s.fem.refactorLatencySteps = p.latency;
    AnastomosisRun a = makeAnastomosisRun(spec, s);
    Result r;
    r.p = p;
    std::vector<double> ms;
    for (size_t f = 0; f < a.frames.size(); ++f) {
        const auto t0 = std::chrono::steady_clock::now();
        const SutureStepStats st = a.sim->step(a.frames[f]);
        ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
        if ((f + 1) % static_cast<size_t>(sample) != 0 || !st.finite) continue;
        const CorotationalFem& fem = a.sim->fem();
        const StaticReference ref = fem.convergedStatic();
        const double e = fem.corotationalEnergy(fem.positions());
        double pos = 0, span = 0;
        for (size_t v = 0; v < ref.x.size(); ++v) {
            pos = std::max(pos, (fem.positions()[v] - ref.x[v]).norm());
            span = std::max(span, (ref.x[v] - fem.restPositions()[v]).norm());
        }
        // A step that leaves the tissue at rest (the needle outside) measures nothing.
        if (!(ref.energy > kEnergyFloor) || !(span > 1e-5)) continue;
        const double rel = std::max(0.0, e - ref.energy) / ref.energy;
        const double relPos = pos / span;
        ++r.samples;
        r.unconverged += !ref.converged;
        r.meanRelEnergy += rel;
        r.maxRelEnergy = std::max(r.maxRelEnergy, rel);
        r.meanPosMm += 1e3 * pos;
        r.maxPosMm = std::max(r.maxPosMm, 1e3 * pos);
        r.meanRelPos += relPos;
        r.maxRelPos = std::max(r.maxRelPos, relPos);
        r.byFrame[f] = {rel, 1e3 * pos, relPos};
        char line[256];
        std::snprintf(line, sizeof line, "%s,%zu,%d,%.6e,%.6e,%.6e,%d,%d,%.3e,%.3e,%.3e,%.1f\n", p.name.c_str(), f,
                      st.activeRows, e, ref.energy, rel, ref.converged, ref.iterations, 1e3 * pos, 1e3 * span, relPos,
                      1e3 * ref.seconds);
        samples << line;
    }
    if (r.samples > 0) {
        r.meanRelEnergy /= r.samples;
        r.meanPosMm /= r.samples;
        r.meanRelPos /= r.samples;
    }
    std::vector<double> sorted = ms;
    std::sort(sorted.begin(), sorted.end());
    for (double x : ms)
        r.meanMs += x / ms.size();
    r.p99Ms = sorted[std::min(sorted.size() - 1, static_cast<size_t>(0.99 * sorted.size()))];
    r.maxMs = sorted.back();
    r.factorizations = a.sim->fem().factorizations();
    return r;
}

} // namespace

int main(int argc, char** argv) {
    std::filesystem::path outDir = "bench_fem_accuracy";
    int sample = 40;
    for (int i = 1; i < argc; ++i) {
        if (!std::strcmp(argv[i], "--sample") && i + 1 < argc)
            sample = std::max(1, std::atoi(argv[++i]));
        else
            outDir = argv[i];
    }
    std::filesystem::create_directories(outDir);
    std::vector<Policy> policies;
    policies.push_back({"linear FEM (rotations never updated)", "linear", false});
    for (double th : {0.01, 0.03, 0.1, 0.25, 0.5}) {
        char name[64];
        std::snprintf(name, sizeof name, "sync_theta%.2f", th);
        policies.push_back({"corotational, synchronous refactor", name, true, RefactorMode::Synchronous, th});
    }
    for (int latency : {30, 120})
        for (double th : {0.03, 0.1, 0.25}) {
            char name[64];
            std::snprintf(name, sizeof name, "background%d_theta%.2f", latency, th);
            policies.push_back(
                {"corotational, background refactor (worker joined " + std::to_string(latency) + " solves later)", name,
                 true, RefactorMode::Background, th, latency});
        }
    std::ofstream samples(outDir / "fem_samples.csv");
    samples << "policy,frame,rows,energy_J,reference_energy_J,rel_energy_error,reference_converged,"
               "reference_iterations,max_position_error_mm,max_displacement_mm,rel_position_error,reference_ms\n";
    std::ofstream table(outDir / "fem_policies.csv");
    table << "policy,refactor_threshold,latency,mean_ms,p99_ms,max_ms,factorizations,samples,unconverged_references,"
             "mean_rel_energy_error,max_rel_energy_error,mean_position_error_mm,max_position_error_mm,"
             "mean_rel_position_error,max_rel_position_error,common_frames,common_mean_rel_energy_error,"
             "common_mean_rel_position_error\n";
    std::printf("%-26s %-8s %-8s %-8s %-7s %-12s %-12s %-10s %-10s %-10s %s\n", "policy", "mean_ms", "p99_ms", "max_ms",
                "factors", "mean_relE", "max_relE", "mean_mm", "max_mm", "mean_relx", "converged/samples");
    std::vector<Result> results;
    for (const Policy& p : policies) {
        results.push_back(run(p, sample, samples));
        const Result& r = results.back();
        std::printf("%-26s %-8.3f %-8.3f %-8.2f %-7d %-12.3e %-12.3e %-10.3e %-10.3e %-10.3e %d/%d\n", p.name.c_str(),
                    r.meanMs, r.p99Ms, r.maxMs, r.factorizations, r.meanRelEnergy, r.maxRelEnergy, r.meanPosMm,
                    r.maxPosMm, r.meanRelPos, r.samples - r.unconverged, r.samples);
        std::fflush(stdout);
    }
    std::vector<size_t> commonFrames;
    for (const auto& [f, sample] : results.front().byFrame)
        if (std::all_of(results.begin(), results.end(), [&](const Result& r) { return r.byFrame.count(f) > 0; }))
            commonFrames.push_back(f);
    std::printf("\nframes measured by every policy: %zu\n%-26s %-12s %-12s\n", commonFrames.size(), "policy",
                "relE_common", "relx_common");
    for (Result& r : results) {
        for (size_t f : commonFrames) {
            r.commonRelEnergy += r.byFrame[f].relEnergy / commonFrames.size();
            r.commonRelPos += r.byFrame[f].relPos / commonFrames.size();
        }
        r.common = static_cast<int>(commonFrames.size());
        std::printf("%-26s %-12.3e %-12.3e\n", r.p.name.c_str(), r.commonRelEnergy, r.commonRelPos);
        char line[512];
        std::snprintf(line, sizeof line,
                      "%s,%.3f,%d,%.4f,%.4f,%.4f,%d,%d,%d,%.6e,%.6e,%.6e,%.6e,%.6e,%.6e,%d,%.6e,%.6e\n",
                      r.p.name.c_str(), r.p.threshold, r.p.latency, r.meanMs, r.p99Ms, r.maxMs, r.factorizations,
                      r.samples, r.unconverged, r.meanRelEnergy, r.maxRelEnergy, r.meanPosMm, r.maxPosMm, r.meanRelPos,
                      r.maxRelPos, r.common, r.commonRelEnergy, r.commonRelPos);
        table << line;
    }
    // One series per family, points in policy order (threshold sweep), x = mean physics ms per step.
    auto plot = [&](const std::string& file, const std::string& yLabel, auto value) {
        std::vector<PlotSeries> series;
        for (const Result& r : results) {
            auto it = std::find_if(series.begin(), series.end(), [&](const auto& s) { return s.label == r.p.family; });
            if (it == series.end()) {
                series.push_back({r.p.family, {}, {}, true});
                it = series.end() - 1;
            }
            it->x.push_back(r.meanMs);
            it->y.push_back(value(r));
        }
        PlotSpec spec;
        spec.title = "Corotational FEM vs converged static solution, anastomosis (2 stitches + pull), " +
                     std::to_string(commonFrames.size()) + " frames; points: refactor threshold 0.5 ... 0.01";
        spec.xLabel = "mean physics time per step (ms)";
        spec.yLabel = yLabel;
        spec.logX = false;
        spec.logY = true;
        return viscera::bench::writeLinePlotPng((outDir / file).string(), spec, series);
    };
    std::string error = plot("fem_error_vs_time.png", "relative energy error (E(x) - E(x*)) / E(x*), mean",
                             [](const Result& r) { return std::max(r.commonRelEnergy, 1e-16); });
    if (error.empty())
        error =
            plot("fem_position_error_vs_time.png", "mean relative position error max|x - x*| / max|x* - X| (X: rest)",
                 [](const Result& r) { return std::max(r.commonRelPos, 1e-16); });
    if (!error.empty()) throw std::runtime_error(error);
    if (!samples || !table) throw std::runtime_error("cannot write the CSV files in " + outDir.string());
    std::printf("\nwrote %s/{fem_policies.csv,fem_samples.csv,fem_error_vs_time.png,fem_position_error_vs_time.png}\n",
                outDir.string().c_str());
    return 0;
}
