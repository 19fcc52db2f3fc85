// Tool–tissue collision comparison of [A §5.2.6]: a rigid cylinder (capsule) is pressed into a
// tissue slab, held, slid over it and held again; the circumsphere, bounding-sphere and polygon
// narrow phases are compared for accuracy (relative error of the mean distance of the collided
// vertices to the cylinder axis against the radius, Fig. 5.10), stability (mean per-frame
// position change of the collided vertices, Fig. 5.12) and time (collision detection and
// response per frame, Fig. 5.13), at 1–20 iterations and for several update thresholds δ
// (Fig. 5.14); plus a tunnelling check at slide speeds up to 0.5 m/s.
//
// Coupling: XPBD runs one substep per XpbdSolver::step() (substeps = 1, dt = frame / S); after
// each substep the collision solver runs `iterations` sweeps and the moves are written back with
// sim::collisionVelocityUpdate (the loop of sim::stepWithCollision, timed here). "iterations" is both the elastic sweeps per substep and
// the collision sweeps per substep.
//
// Run: ./build/bench/bench_collision [output-dir] [--quick]   (default ./collision_out)
#include "line_plot.hpp"

#include "sim/collision/collision_solver.hpp"
#include "sim/collision/distance.hpp"
#include "sim/diagnostics/stability_check.hpp"
#include "sim/mesh/generators.hpp"
#include "sim/scene/tool_probe.hpp"
#include "sim/xpbd/xpbd_solver.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

using namespace viscera::sim;

namespace {

constexpr double kFrame = 1.0 / 60.0;
constexpr double kTop = 0.02;       // slab top, m
constexpr double kRadius = 0.01;    // cylinder radius, m
constexpr double kHalfLen = 0.03;   // cylinder half length (along y), m
constexpr double kDepth = 0.005;    // indentation, m
constexpr double kSlide = 0.04;     // slide distance along x, m

struct Slab {
    std::unique_ptr<TetMesh> mesh;
    std::vector<int32_t> fixed;
    std::vector<double> invMass;
    std::vector<int32_t> topVertices;
    Material material;
    int substeps = 20;
};

Slab makeSlab() {
    Slab s;
    s.mesh = makeBoxTetMesh({Vec3::Zero(), Vec3(0.1, 0.1, kTop), {14, 14, 3}});
    s.mesh->requireLevel(3);
    for (int32_t v = 0; v < static_cast<int32_t>(s.mesh->vertexCount()); ++v) {
        if (s.mesh->positions()[v].z() < 1e-9) s.fixed.push_back(v);
        if (s.mesh->positions()[v].z() > kTop - 1e-9) s.topVertices.push_back(v);
    }
    s.material.youngsModulus = 10000;
    s.material.poissonRatio = 0.3;
    const std::vector<double> m = lumpedMasses(*s.mesh, s.material.density, s.fixed);
    s.invMass.resize(m.size());
    for (size_t v = 0; v < m.size(); ++v) s.invMass[v] = m[v] > 0 ? 1.0 / m[v] : 0.0;
    // Substeps from the load-time stability check.
    XpbdSettings probe;
    probe.substeps = s.substeps;
    auto tmp = XpbdSolver::create(*s.mesh, s.material, s.fixed, probe);
    const StabilityFigures f = assessStability(*s.mesh, tmp->model(), s.material.density, {}, probe);
    s.substeps = std::max(s.substeps, f.requiredSubsteps);
    return s;
}

ToolShape::Pose cylinderPose(double x, double z) {
    ToolShape::Pose p = ToolShape::Pose::Identity();
    p.linear() = Eigen::AngleAxisd(M_PI / 2, Vec3::UnitZ()).toRotationMatrix(); // tool x → world y
    p.translation() = Vec3(x, 0.05, z);
    return p;
}

struct RunSpec {
    CollisionMethod method = CollisionMethod::Circumsphere;
    double delta = 0.3;
    int iterations = 5;
    double speed = 0.1; // m/s, slide
};

struct RunResult {
    RunSpec spec;
    double relErrMean = 0, relErrMin = 0, relErrMax = 0;
    double stabilityHold = 0, stabilitySlide = 0; // m per frame
    double collisionMs = 0, frameMs = 0;          // per frame
    double factorUpdatesPerFrame = 0, contactVerticesMean = 0;
    int tunnelledMax = 0;      // most tunnelled vertices in one frame
    int tunnelledFrames = 0;
    double deepestInside = 0;  // m, most negative signed distance of a surface vertex
    bool finite = true;
};

/// Vertices that went through the tool: deeper than 1 mm inside it, or top-surface vertices that
/// ended above the axis within the cylinder's footprint (the tissue closed over the tool).
int countTunnelled(const std::vector<Vec3>& x, const Slab& slab, const ToolShape& tool,
                   double& deepest) {
    const Capsule& c = tool.parts()[0];
    int n = 0;
    for (int32_t v : slab.topVertices) {
        const double d = tool.signedDistance(x[v]);
        deepest = std::min(deepest, d);
        const Vec3 ax = c.a + closestParameterOnSegment(x[v], c.a, c.b) * (c.b - c.a);
        const bool overTop = x[v].z() > ax.z() && std::abs(x[v].x() - ax.x()) < kRadius &&
                             x[v].y() > std::min(c.a.y(), c.b.y()) &&
                             x[v].y() < std::max(c.a.y(), c.b.y());
        if (d < -1e-3 || overTop) ++n;
    }
    return n;
}

RunResult run(const Slab& slab, const RunSpec& spec) {
    using Clock = std::chrono::steady_clock;
    RunResult r;
    r.spec = spec;
    XpbdSettings xs;
    xs.dt = kFrame / slab.substeps;
    xs.substeps = 1;
    xs.iterations = spec.iterations;
    xs.threads = 1;
    auto solver = XpbdSolver::create(*slab.mesh, slab.material, slab.fixed, xs);
    CollisionSettings cs;
    cs.method = spec.method;
    cs.circumsphere.updateThreshold = spec.delta;
    cs.polygonMargin = 1e-3;
    auto col = CollisionSolver::create(CollisionSurfaceDesc::fromTetMesh(*slab.mesh, slab.invMass), cs);
    ToolShape tool = ToolShape::capsule(kHalfLen, kRadius);

    const double x0 = 0.03, zStart = kTop + kRadius + 0.002, zPress = kTop + kRadius - kDepth;
    const int pressFrames = 12, holdFrames = 15, slideFrames =
        static_cast<int>(std::ceil(kSlide / (spec.speed * kFrame))), endFrames = 10;
    struct Key { double x, z; };
    std::vector<Key> keys; // tool pose at the end of each frame
    for (int f = 1; f <= pressFrames; ++f)
        keys.push_back({x0, zStart + (zPress - zStart) * f / pressFrames});
    for (int f = 0; f < holdFrames; ++f) keys.push_back({x0, zPress});
    for (int f = 1; f <= slideFrames; ++f)
        keys.push_back({x0 + std::min(kSlide, spec.speed * kFrame * f), zPress});
    for (int f = 0; f < endFrames; ++f) keys.push_back({x0 + kSlide, zPress});

    ToolShape::Pose prev = cylinderPose(x0, zStart);
    tool.setPose(prev);
    std::vector<Vec3> last = solver->positions();
    double errSum = 0, holdSum = 0, slideSum = 0, colTime = 0, frameTime = 0, updates = 0,
           contactSum = 0;
    int errN = 0, holdN = 0, slideN = 0;
    r.relErrMin = 1e300;
    r.relErrMax = -1e300;
    const int holdStart = pressFrames + 5, slideStart = pressFrames + holdFrames;
    for (size_t f = 0; f < keys.size(); ++f) {
        const ToolShape::Pose next = cylinderPose(keys[f].x, keys[f].z);
        // Same loop as stepWithCollision, with the collision part timed on its own.
        const auto t0 = Clock::now();
        double ct = 0;
        for (int s = 1; s <= slab.substeps; ++s) {
            tool.setPose(interpolatePose(prev, next, static_cast<double>(s) / slab.substeps));
            if (!solver->step().finite) r.finite = false;
            std::vector<Vec3> x = solver->positions();
            const auto c0 = Clock::now();
            col->beginStep(x, tool, xs.dt);
            for (int k = 0; k < spec.iterations; ++k) col->iterate(x, tool);
            ct += std::chrono::duration<double>(Clock::now() - c0).count();
            updates += col->stats().factorUpdates;
            if (col->stats().candidates == 0) continue;
            std::vector<Vec3> v = solver->velocities();
            const auto& before = solver->positions();
            collisionVelocityUpdate(before, x, v);
            solver->setState(x, v);
        }
        frameTime += std::chrono::duration<double>(Clock::now() - t0).count();
        colTime += ct;
        prev = next;
        const std::vector<Vec3>& x = solver->positions();
        for (const Vec3& p : x)
            if (!p.allFinite() || p.norm() > 1.0) r.finite = false; // diverged
        if (!r.finite) break;
        const int tun = countTunnelled(x, slab, tool, r.deepestInside);
        r.tunnelledMax = std::max(r.tunnelledMax, tun);
        r.tunnelledFrames += tun > 0;
        const std::vector<int32_t>& cv = col->contactVertices();
        if (static_cast<int>(f) >= holdStart && !cv.empty()) {
            const Capsule& c = tool.parts()[0];
            double d = 0, move = 0;
            for (int32_t v : cv) {
                d += (x[v] - (c.a + closestParameterOnSegment(x[v], c.a, c.b) * (c.b - c.a))).norm();
                move += (x[v] - last[v]).norm();
            }
            d /= cv.size();
            move /= cv.size();
            const double rel = (d - kRadius) / kRadius;
            errSum += rel;
            ++errN;
            r.relErrMin = std::min(r.relErrMin, rel);
            r.relErrMax = std::max(r.relErrMax, rel);
            contactSum += cv.size();
            if (static_cast<int>(f) < slideStart) {
                holdSum += move;
                ++holdN;
            } else {
                slideSum += move;
                ++slideN;
            }
        }
        last = x;
    }
    const double frames = static_cast<double>(keys.size());
    r.relErrMean = errN ? errSum / errN : std::numeric_limits<double>::quiet_NaN();
    if (!errN) r.relErrMin = r.relErrMax = std::numeric_limits<double>::quiet_NaN();
    r.stabilityHold = holdN ? holdSum / holdN : 0;
    r.stabilitySlide = slideN ? slideSum / slideN : 0;
    r.collisionMs = 1e3 * colTime / frames;
    r.frameMs = 1e3 * frameTime / frames;
    r.factorUpdatesPerFrame = updates / frames;
    r.contactVerticesMean = errN ? contactSum / errN : 0;
    return r;
}

std::string deltaName(double d) {
    if (!std::isfinite(d)) return "inf";
    char b[32];
    std::snprintf(b, sizeof b, "%g", d);
    return b;
}

std::string label(const RunSpec& s) {
    std::string l = toString(s.method);
    if (s.method == CollisionMethod::Circumsphere) l += " d=" + deltaName(s.delta);
    return l;
}

void printRow(const RunResult& r) {
    std::printf("%-24s %4d %6.2f %+9.4f %+9.4f %+9.4f %10.3e %10.3e %8.3f %8.2f %7.1f %6d %5d %+8.2e%s\n",
                label(r.spec).c_str(), r.spec.iterations, r.spec.speed, r.relErrMean, r.relErrMin,
                r.relErrMax, r.stabilityHold, r.stabilitySlide, r.collisionMs, r.frameMs,
                r.factorUpdatesPerFrame, r.tunnelledMax, r.tunnelledFrames, r.deepestInside,
                r.finite ? "" : "  DIVERGED");
    std::fflush(stdout);
}

void writeRow(std::ofstream& o, const RunResult& r) {
    o << toString(r.spec.method) << ',' << deltaName(r.spec.delta) << ',' << r.spec.iterations << ','
      << r.spec.speed << ',' << r.relErrMean << ',' << r.relErrMin << ',' << r.relErrMax << ','
      << r.stabilityHold << ',' << r.stabilitySlide << ',' << r.collisionMs << ',' << r.frameMs
      << ',' << r.factorUpdatesPerFrame << ',' << r.contactVerticesMean << ',' << r.tunnelledMax
      << ',' << r.tunnelledFrames << ',' << r.deepestInside << ',' << (r.finite ? 1 : 0) << '\n';
}

const char* kHeader =
    "method,delta,iterations,speed_m_s,rel_err_mean,rel_err_min,rel_err_max,stability_hold_m,"
    "stability_slide_m,collision_ms,frame_ms,factor_updates_per_frame,contact_vertices_mean,"
    "tunnelled_max,tunnelled_frames,deepest_inside_m,finite\n";

} // namespace

int main(int argc, char** argv) {
    std::filesystem::path outDir = "collision_out";
    bool quick = false;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "-h" || a == "--help") {
            std::fprintf(stderr, "usage: bench_collision [output-dir] [--quick]\n");
            return 0;
        }
        if (a == "--quick") quick = true;
        else outDir = a;
    }
    std::filesystem::create_directories(outDir);
    const Slab slab = makeSlab();
    std::printf("slab 10 x 10 x 2 cm: %zu tets, %zu nodes, %zu surface triangles; E = %.0f Pa, "
                "nu = %.2f; %d substeps per 1/60 s frame; cylinder r = %.0f mm pressed %.0f mm\n",
                slab.mesh->tetCount(), slab.mesh->vertexCount(),
                slab.mesh->boundary().triangleCount(), slab.material.youngsModulus,
                slab.material.poissonRatio, slab.substeps, kRadius * 1e3, kDepth * 1e3);
    const std::vector<int> iterations = quick ? std::vector<int>{1, 5} : std::vector<int>{1, 2, 3, 5, 10, 20};
    const std::vector<double> deltas = quick ? std::vector<double>{0, 0.3}
                                             : std::vector<double>{0, 0.1, 0.3, 0.7, 0.9,
                                                                   std::numeric_limits<double>::infinity()};
    const std::vector<CollisionMethod> methods = {CollisionMethod::Circumsphere,
                                                  CollisionMethod::BoundingSphere,
                                                  CollisionMethod::Polygon};
    std::printf("\n%-24s %4s %6s %9s %9s %9s %10s %10s %8s %8s %7s %6s %5s %9s\n", "method", "it",
                "v m/s", "relErr", "relErrMin", "relErrMax", "stab_hold", "stab_slide", "col_ms",
                "frame_ms", "upd/fr", "tunMax", "tunFr", "deepest");
    std::ofstream sweep(outDir / "collision_sweep.csv");
    sweep << kHeader;
    std::vector<RunResult> main;
    for (CollisionMethod m : methods)
        for (int k : iterations) {
            RunSpec s{m, 0.3, k, 0.1};
            main.push_back(run(slab, s));
            printRow(main.back());
            writeRow(sweep, main.back());
        }
    // δ sweep (circumsphere) at 2 and 5 iterations.
    std::vector<RunResult> deltaRuns;
    for (int k : quick ? std::vector<int>{5} : std::vector<int>{2, 5})
        for (double d : deltas) {
            RunSpec s{CollisionMethod::Circumsphere, d, k, 0.1};
            deltaRuns.push_back(run(slab, s));
            printRow(deltaRuns.back());
            writeRow(sweep, deltaRuns.back());
        }
    // Tunnelling: slide speeds up to 0.5 m/s.
    std::ofstream tunnel(outDir / "collision_tunnelling.csv");
    tunnel << kHeader;
    std::vector<RunResult> tunRuns;
    for (double v : quick ? std::vector<double>{0.5} : std::vector<double>{0.1, 0.25, 0.5})
        for (CollisionMethod m : methods)
            for (int k : quick ? std::vector<int>{1} : std::vector<int>{1, 3, 5}) {
                RunSpec s{m, 0.3, k, v};
                tunRuns.push_back(run(slab, s));
                printRow(tunRuns.back());
                writeRow(tunnel, tunRuns.back());
            }
    if (!sweep || !tunnel) {
        std::fprintf(stderr, "bench_collision: cannot write CSV files in %s\n", outDir.string().c_str());
        return 1;
    }

    // Plots: the three criteria against iterations, and against δ.
    using viscera::bench::PlotSeries;
    using viscera::bench::PlotSpec;
    auto byIterations = [&](auto value) {
        std::vector<PlotSeries> out;
        for (CollisionMethod m : methods) {
            PlotSeries s;
            s.label = toString(m);
            s.markers = true;
            for (const RunResult& r : main)
                if (r.spec.method == m) {
                    s.x.push_back(r.spec.iterations);
                    s.y.push_back(value(r));
                }
            out.push_back(s);
        }
        return out;
    };
    std::string error;
    auto plot = [&](const std::string& file, PlotSpec spec, const std::vector<PlotSeries>& series) {
        spec.width = 1200;
        spec.height = 700;
        if (error.empty()) error = viscera::bench::writeLinePlotPng((outDir / file).string(), spec, series);
    };
    PlotSpec spec;
    spec.xLabel = "iterations per substep (log scale)";
    spec.logX = true;
    spec.logY = false;
    spec.title = "Accuracy: relative error of mean collided-vertex distance to the axis (Fig. 5.10)";
    spec.yLabel = "(d_ave - r) / r";
    spec.yMarks = {0.0};
    plot("accuracy_vs_iterations.png", spec, byIterations([](const RunResult& r) { return r.relErrMean; }));
    spec.yMarks.clear();
    spec.logY = true;
    spec.title = "Stability: mean per-frame move of collided vertices, tool held (Fig. 5.12)";
    spec.yLabel = "m per frame";
    plot("stability_hold_vs_iterations.png", spec, byIterations([](const RunResult& r) { return r.stabilityHold; }));
    spec.title = "Stability: mean per-frame move of collided vertices, tool sliding 0.1 m/s";
    plot("stability_slide_vs_iterations.png", spec, byIterations([](const RunResult& r) { return r.stabilitySlide; }));
    spec.title = "Time: collision detection and response per frame (Fig. 5.13)";
    spec.yLabel = "ms per frame";
    plot("time_vs_iterations.png", spec, byIterations([](const RunResult& r) { return r.collisionMs; }));
    // δ plots (finite δ only; δ = inf is in the CSV).
    auto byDelta = [&](auto value) {
        std::vector<PlotSeries> out;
        for (int k : quick ? std::vector<int>{5} : std::vector<int>{2, 5}) {
            PlotSeries s;
            s.label = "circumsphere, " + std::to_string(k) + " it";
            s.markers = true;
            for (const RunResult& r : deltaRuns)
                if (r.spec.iterations == k && std::isfinite(r.spec.delta)) {
                    s.x.push_back(r.spec.delta);
                    s.y.push_back(value(r));
                }
            out.push_back(s);
        }
        return out;
    };
    PlotSpec ds;
    ds.logX = false;
    ds.logY = false;
    ds.xLabel = "update threshold delta";
    ds.title = "Update threshold: accuracy (Fig. 5.14)";
    ds.yLabel = "(d_ave - r) / r";
    plot("accuracy_vs_delta.png", ds, byDelta([](const RunResult& r) { return r.relErrMean; }));
    ds.title = "Update threshold: stability, tool held";
    ds.yLabel = "m per frame";
    plot("stability_vs_delta.png", ds, byDelta([](const RunResult& r) { return r.stabilityHold; }));
    ds.title = "Update threshold: collision time per frame";
    ds.yLabel = "ms per frame";
    plot("time_vs_delta.png", ds, byDelta([](const RunResult& r) { return r.collisionMs; }));
    if (!error.empty()) {
        std::fprintf(stderr, "bench_collision: %s\n", error.c_str());
        return 1;
    }
    std::printf("\nwrote %s/{collision_sweep.csv,collision_tunnelling.csv,*_vs_iterations.png,"
                "*_vs_delta.png}\n", outDir.string().c_str());
    return 0;
}
