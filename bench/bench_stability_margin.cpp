// Where plain XPBD actually becomes unstable, against the load-time stiffness number
// (sim/diagnostics/stability_check.hpp).
//
// Each body runs at a list of substep counts (1 iteration per substep, 1/60 s frames, damping
// 2/s, gravity) from rest plus a velocity kick: a seeded random velocity of 5 cm/s rms on every
// free node, which puts energy into the highest modes of the mesh, where an unstable integrator
// shows first. Every frame the invariants of the stability suite are checked: all values finite,
// total energy (elastic + kinetic + gravity) never above the start by more than 5 % of the body's
// gravity scale m g L, and after the run the body settles (kinetic energy per kilogram below
// 3e-4 J/kg, the suite's 1e-5 J on its 34 g block). The load check's figures at that substep
// count are written next to what the run did, so the margin of the rule can be read off.
//
// Bodies: the tissue-slab sample (5 mm cells, 30 kPa), the rectum sample's fat pad (2 × 2 × 4 mm
// cells, 3 kPa, bottom fixed), the 30,000-tet bench block (1 cm cells, 20 kPa) and the stability
// suite's cantilever (1 cm cells, 20 kPa) at ν = 0.45, 0.49 and 0.499; optional extra bodies from
// .vtet files (e.g. the CGAL meshes of the organ-blob and liver samples, unpacked from their cases),
// fixed where the sample fixes them is not known here: their nodes below the 5th height percentile.
//
// Usage: bench_stability_margin [output-dir] [--frames N] [--vtet name:E:nu:density:path ...]
// Writes <dir>/stability_margin.csv: body,nu,tets,substeps,stiffness_number,accepted,finite,
// max_energy_gain_rel,final_ke_per_kg,settled,speed_clamps,ms_per_frame, and
// <dir>/stability_margin.png (energy gain against s, log-log, one line per body).
#include "line_plot.hpp"
#include "sample_bodies.hpp"

#include "sim/diagnostics/stability_check.hpp"
#include "sim/material/material.hpp"
#include "sim/xpbd/xpbd_solver.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

using namespace viscera::sim;
using viscera::bench::boxBody;
using viscera::bench::SampleBody;
using viscera::bench::sampleBoxBodies;
using viscera::bench::vtetBody;

namespace {

constexpr double kPlotFloor = 1e-5; ///< no energy gain at all is drawn here on the log axis

struct Run {
    bool finite = true;
    double maxGainRel = 0, finalKePerKg = 0, msPerFrame = 0;
    int clamps = 0;
};

Run run(const SampleBody& b, int substeps, int frames) {
    XpbdSettings s;
    s.substeps = substeps;
    s.damping = 2.0;
    TetBodyDesc d;
    d.name = b.name;
    d.mesh = b.mesh.get();
    d.model = makeConstraintModel(b.material, b.name);
    d.density = b.material.density;
    d.fixedNodes = b.fixed;
    auto solver = XpbdSolver::create(d, s);
    std::mt19937 rng(7);
    std::normal_distribution<double> n(0.0, 0.05 / std::sqrt(3.0));
    std::vector<Vec3> v(b.mesh->vertexCount());
    for (Vec3& vi : v)
        vi = Vec3(n(rng), n(rng), n(rng));
    for (int32_t f : b.fixed)
        v[f].setZero();
    solver->setState(b.mesh->positions(), v);
    const double mass = solver->totalMass();
    const double scale = mass * 9.81 * b.extent;
    const double e0 = solver->elasticEnergy() + solver->kineticEnergy() + solver->potentialEnergy();
    Run r;
    const auto t0 = std::chrono::steady_clock::now();
    for (int f = 0; f < frames; ++f) {
        const StepStats st = solver->step();
        r.clamps += st.speedClamps;
        const double e = solver->elasticEnergy() + solver->kineticEnergy() + solver->potentialEnergy();
        if (!st.finite || !std::isfinite(e)) {
            r.finite = false;
            break;
        }
        r.maxGainRel = std::max(r.maxGainRel, (e - e0) / scale);
    }
    r.msPerFrame = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count() / frames;
    r.finalKePerKg = solver->kineticEnergy() / mass;
    return r;
}

} // namespace

int main(int argc, char** argv) {
    std::filesystem::path out = "stability_margin_out";
    int frames = 240;
    std::vector<std::string> extra;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--frames" && i + 1 < argc)
            frames = std::max(1, std::atoi(argv[++i]));
        else if (a == "--vtet" && i + 1 < argc)
            extra.push_back(argv[++i]);
        else
            out = a;
    }
    std::vector<SampleBody> bodies = sampleBoxBodies();
    for (double nu : {0.45, 0.49, 0.499})
        bodies.push_back(
            boxBody("cantilever", {Vec3::Zero(), Vec3(0.08, 0.02, 0.02), {8, 2, 2}}, 20000, nu, 1050, false));
    try {
        for (const std::string& spec : extra)
            bodies.push_back(vtetBody(spec));
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bench_stability_margin: %s\n", e.what());
        return 2;
    }
    std::filesystem::create_directories(out);
    std::ofstream csv(out / "stability_margin.csv");
    csv << "body,nu,tets,substeps,stiffness_number,accepted,finite,max_energy_gain_rel,final_ke_per_kg,settled,"
           "speed_clamps,ms_per_frame\n";
    std::vector<viscera::bench::PlotSeries> plot;
    for (const SampleBody& b : bodies) {
        const auto model = makeConstraintModel(b.material, b.name);
        viscera::bench::PlotSeries series;
        char label[160];
        std::snprintf(label, sizeof label, "%s, %zu tets, nu %.3f", b.name.c_str(), b.mesh->tetCount(),
                      b.material.poissonRatio);
        series.label = label;
        series.markers = true;
        for (int substeps : {5, 10, 15, 20, 30, 40, 60, 100}) {
            XpbdSettings s;
            s.substeps = substeps;
            const StabilityFigures fig = assessStability(*b.mesh, *model, b.material.density, {}, s);
            const Run r = run(b, substeps, frames);
            const bool settled = r.finite && r.finalKePerKg < 3e-4;
            char line[512];
            std::snprintf(line, sizeof line, "%s,%.3f,%zu,%d,%.4g,%d,%d,%.4g,%.4g,%d,%d,%.3f\n", b.name.c_str(),
                          b.material.poissonRatio, b.mesh->tetCount(), substeps, fig.maxStiffnessNumber,
                          fig.ok() ? 1 : 0, r.finite ? 1 : 0, r.maxGainRel, r.finalKePerKg, settled ? 1 : 0, r.clamps,
                          r.msPerFrame);
            csv << line;
            std::fputs(line, stdout);
            std::fflush(stdout);
            series.x.push_back(fig.maxStiffnessNumber);
            series.y.push_back(std::max(r.finite ? r.maxGainRel : 1e3, kPlotFloor));
        }
        plot.push_back(std::move(series));
    }
    viscera::bench::PlotSpec spec;
    spec.title = "Energy gain of plain XPBD against the stiffness number (load rule refuses s > 1)";
    spec.xLabel = "largest stiffness number s = k w h^2 / (rho L^2) (log scale; fewer substeps to the right)";
    spec.yLabel = "max energy gain / (m g L) (log; 1e-5 = no gain; 0.05 = the suite's bound)";
    spec.logX = true;
    spec.yMarks = {0.05};
    spec.yMin = kPlotFloor;
    if (const std::string e = viscera::bench::writeLinePlotPng((out / "stability_margin.png").string(), spec, plot);
        !e.empty()) {
        std::fprintf(stderr, "bench_stability_margin: %s\n", e.c_str());
        return 1;
    }
    std::printf("wrote %s and stability_margin.png\n", (out / "stability_margin.csv").string().c_str());
    return 0;
}
