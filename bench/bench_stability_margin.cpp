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
// Writes <dir>/stability_margin.csv: body,nu,substeps,stiffness_number,accepted,finite,
// max_energy_gain_rel,final_ke_per_kg,settled,speed_clamps,ms_per_frame.
#include "sim/diagnostics/stability_check.hpp"
#include "sim/material/material.hpp"
#include "sim/mesh/generators.hpp"
#include "sim/mesh/tet_io.hpp"
#include "sim/xpbd/xpbd_solver.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

using namespace viscera::sim;

namespace {

struct Body {
    std::string name;
    std::unique_ptr<TetMesh> mesh;
    std::vector<int32_t> fixed;
    Material material;
    double scaleLength = 0.08; ///< m, for the gravity energy scale m g L
};

Material snh(double E, double nu, double density) {
    Material m;
    m.model = MaterialModel::StableNeoHookean;
    m.youngsModulus = E;
    m.poissonRatio = nu;
    m.density = density;
    return m;
}

Body box(std::string name, const BoxSpec& spec, const Material& m, bool fixBottom) {
    Body b;
    b.name = std::move(name);
    b.mesh = makeBoxTetMesh(spec);
    b.material = m;
    b.scaleLength = spec.size.maxCoeff();
    for (int32_t v = 0; v < static_cast<int32_t>(b.mesh->vertexCount()); ++v) {
        const Vec3& p = b.mesh->positions()[v];
        const bool fix = fixBottom ? p.z() < spec.origin.z() + 1e-9 : p.x() < spec.origin.x() + 1e-9;
        if (fix) b.fixed.push_back(v);
    }
    return b;
}

struct Run {
    bool finite = true;
    double maxGainRel = 0, finalKePerKg = 0, msPerFrame = 0;
    int clamps = 0;
};

Run run(const Body& b, int substeps, int frames) {
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
    const double scale = mass * 9.81 * b.scaleLength;
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
    std::vector<Body> bodies;
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
    bodies.push_back(
        box("tissue-slab", {Vec3::Zero(), Vec3(0.08, 0.04, 0.03), {16, 8, 6}}, snh(30000, 0.45, 1050), false));
    bodies.push_back(box("rectum-fat", {Vec3(-0.06, -0.05, -0.008), Vec3(0.12, 0.10, 0.008), {60, 50, 2}},
                         snh(3000, 0.45, 950), true));
    bodies.push_back(
        box("block30k", {Vec3::Zero(), Vec3(0.25, 0.2, 0.1), {25, 20, 10}}, snh(20000, 0.45, 1050), false));
    for (double nu : {0.45, 0.49, 0.499})
        bodies.push_back(
            box("cantilever", {Vec3::Zero(), Vec3(0.08, 0.02, 0.02), {8, 2, 2}}, snh(20000, nu, 1050), false));
    for (const std::string& spec : extra) {
        // name:E:nu:density:path
        std::vector<std::string> f;
        std::stringstream ss(spec);
        for (std::string part; std::getline(ss, part, ':');)
            f.push_back(part);
        if (f.size() != 5) {
            std::fprintf(stderr, "bench_stability_margin: --vtet %s: expected name:E:nu:density:path\n", spec.c_str());
            return 2;
        }
        std::ifstream in(f[4]);
        std::stringstream text;
        text << in.rdbuf();
        Body b;
        b.name = f[0];
        b.mesh = parseVtet(text.str(), f[4]);
        b.material = snh(std::stod(f[1]), std::stod(f[2]), std::stod(f[3]));
        std::vector<double> z;
        for (const Vec3& p : b.mesh->positions())
            z.push_back(p.z());
        std::vector<double> sorted = z;
        std::sort(sorted.begin(), sorted.end());
        const double cut = sorted[sorted.size() / 20];
        for (size_t v = 0; v < z.size(); ++v)
            if (z[v] <= cut) b.fixed.push_back(static_cast<int32_t>(v));
        const auto lo = b.mesh->positions()[0];
        double ext = 0;
        for (const Vec3& p : b.mesh->positions())
            ext = std::max(ext, (p - lo).norm());
        b.scaleLength = ext;
        bodies.push_back(std::move(b));
    }
    std::filesystem::create_directories(out);
    std::ofstream csv(out / "stability_margin.csv");
    csv << "body,nu,tets,substeps,stiffness_number,accepted,finite,max_energy_gain_rel,final_ke_per_kg,settled,"
           "speed_clamps,ms_per_frame\n";
    for (const Body& b : bodies) {
        const auto model = makeConstraintModel(b.material, b.name);
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
        }
    }
    std::printf("wrote %s\n", (out / "stability_margin.csv").string().c_str());
    return 0;
}
