// Tool–tissue collision comparison of [A §5.2.6]: a rigid capsule is pressed into a tissue slab,
// held, slid over it and held again; the circumsphere, bounding-sphere and polygon (1 mm margin;
// [Eri04] per-feature constraints as in the thesis, and one closest-feature constraint per pair)
// narrow phases are compared for accuracy (relative error of the mean distance of the collided
// vertices to the tool axis against the radius, Fig. 5.10), stability (mean per-frame position
// change of the collided vertices, Fig. 5.12: "hold" over frames 5–40 after the press, which
// includes the settling after the press; "steady" over the last 20 of them, the jitter of a
// resting contact; "slide" while the tool slides) and time (collision detection and response
// per frame, Fig. 5.13), at 1–20 iterations and for several update thresholds δ (Fig. 5.14); and
// tunnelling at slide speeds 0.05–0.5 m/s. Collided vertices: those of the triangles in contact
// during the frame's last substep.
//
// Set-up (the thesis experiment as far as it is described):
//   - slab 6 × 3.6 × 1.2 cm, 4 mm cells (2,430 tets), E = 10 kPa, ν = 0.3, bottom fixed;
//     XPBD with 20 substeps per 1/60 s frame and k iterations (sweeps) per substep;
//   - two tools, same for every method: the 10 mm cylinder of Fig. 5.8 (pressed 5 mm, its axis
//     stays above the tissue) and a 2.5 mm instrument shaft (pressed 4 mm, its axis 1.5 mm below
//     the undeformed surface);
//   - coupling "iter" (default): the contact constraints are projected inside the XPBD iteration,
//     after every elastic sweep (sim::makeCollisionHook's loop, timed here), multipliers reset
//     each substep; k is then both the elastic and the collision sweeps per substep. The tool
//     pose comes from the "device" once per frame and holds for all substeps ("frame" poses: at
//     0.5 m/s the tool jumps 8.3 mm per frame). Reference variants: "iter+interp" (pose
//     interpolated every substep) and "post+interp" (the earlier coupling: k collision sweeps
//     after each substep's elastic sweeps, sim::stepWithCollision).
//
// Tunnelling, counted per frame after the step, over the top-surface vertices:
//   - "over": the vertex lies within the tool's footprint seen from above (horizontal distance
//     to the closest axis point < r, axis parameter strictly inside the segment) and above the
//     axis (z > axis z): the surface passes over the tool's centre line, i.e. the tool went
//     through the surface into the tissue;
//   - "inside": the vertex is inside the tool deeper than 1 mm (a contact missed or lost).
// A frame with any such vertex is a tunnelled frame.
//
// Run: ./build/bench/bench_collision [output-dir] [--quick]   (default ./collision_out)
//      ./build/bench/bench_collision --trace [tool 0|1] [method 0..3] [iterations] [delta]
//                                    [speed] [energy scale ς] [h 1/m] [θ deg] [safe cone 1|0]
//        (one run, per-frame figures; methods 0 circumsphere, 1 bounding sphere, 2 polygon,
//        3 polygon_features)
//
// The comparison also runs the circumsphere with contacts through the whole sphere (safe cone
// off, CollisionSettings::safeConeOnly = false) to show what that test is for.
#include "line_plot.hpp"

#include "sim/collision/collision_solver.hpp"
#include "sim/collision/distance.hpp"
#include "sim/diagnostics/stability_check.hpp"
#include "sim/mesh/generators.hpp"
#include "sim/scene/tool_probe.hpp"
#include "sim/util/format.hpp"
#include "sim/xpbd/xpbd_solver.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

using namespace viscera::sim;

namespace {

constexpr double kFrame = 1.0 / 60.0;
constexpr double kLx = 0.06, kLy = 0.036, kTop = 0.012; // slab, m
constexpr double kHalfLen = 0.012;                      // tool half length (along y), m
constexpr double kSlide = 0.03;                         // slide distance along x, m
constexpr double kX0 = 0.015;                           // tool x at the start, m
bool g_trace = false;                                   // --trace: per-frame figures of one run

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
    s.mesh = makeBoxTetMesh({Vec3::Zero(), Vec3(kLx, kLy, kTop), {15, 9, 3}});
    s.mesh->requireLevel(3);
    for (int32_t v = 0; v < static_cast<int32_t>(s.mesh->vertexCount()); ++v) {
        if (s.mesh->positions()[v].z() < 1e-9) s.fixed.push_back(v);
        if (s.mesh->positions()[v].z() > kTop - 1e-9) s.topVertices.push_back(v);
    }
    s.material.youngsModulus = 10000;
    s.material.poissonRatio = 0.3;
    const std::vector<double> m = lumpedMasses(*s.mesh, s.material.density, s.fixed);
    s.invMass.resize(m.size());
    for (size_t v = 0; v < m.size(); ++v)
        s.invMass[v] = m[v] > 0 ? 1.0 / m[v] : 0.0;
    XpbdSettings probe;
    probe.substeps = s.substeps;
    auto tmp = XpbdSolver::create(*s.mesh, s.material, s.fixed, probe);
    const StabilityFigures f = assessStability(*s.mesh, tmp->model(), s.material.density, {}, probe);
    s.substeps = std::max(s.substeps, f.requiredSubsteps);
    return s;
}

struct Tool {
    const char* name;
    double radius, depth; // m
};
const Tool kCylinder{"cyl_r10", 0.010, 0.005};
const Tool kShaft{"shaft_r2.5", 0.0025, 0.004};

ToolShape::Pose toolPose(double x, double z) {
    ToolShape::Pose p = ToolShape::Pose::Identity();
    p.linear() = Eigen::AngleAxisd(M_PI / 2, Vec3::UnitZ()).toRotationMatrix(); // tool x → world y
    p.translation() = Vec3(x, kLy / 2, z);
    return p;
}

enum class Coupling { InIteration, InIterationInterp, PostSubstepInterp };
const char* couplingName(Coupling c) {
    switch (c) {
    case Coupling::InIteration:
        return "iter";
    case Coupling::InIterationInterp:
        return "iter+interp";
    case Coupling::PostSubstepInterp:
        return "post+interp";
    }
    return "?";
}

struct RunSpec {
    Tool tool = kCylinder;
    CollisionMethod method = CollisionMethod::Circumsphere;
    double delta = CircumsphereParams{}.updateThreshold;
    int iterations = 5;
    double speed = 0.1; // m/s, slide
    Coupling coupling = Coupling::InIteration;
    double energyScale = CircumsphereParams{}.energyScale;               // ς, m (--trace only)
    double curvatureThreshold = CircumsphereParams{}.curvatureThreshold; // h, 1/m (--trace only)
    double safeAngle = CircumsphereParams{}.safeAngle;                   // θ, rad (--trace only)
    bool safeCone = CollisionSettings{}.safeConeOnly;                    // contacts only through the safe cone
};

struct RunResult {
    RunSpec spec;
    double relErrMean = 0, relErrMin = 0, relErrMax = 0;
    double stabilityHold = 0, stabilitySteady = 0, stabilitySlide = 0; // m per frame
    double collisionMs = 0, frameMs = 0;                               // per frame
    double factorUpdatesPerFrame = 0, contactVerticesMean = 0;
    int tunnelledFrames = 0, tunnelledMax = 0, overFrames = 0, insideFrames = 0;
    double deepestInside = 0; // m, most negative signed distance of a top vertex
    bool finite = true;
};

struct TunnelCount {
    int over = 0, inside = 0;
};

TunnelCount countTunnelled(const std::vector<Vec3>& x, const Slab& slab, const ToolShape& tool, double& deepest) {
    const Capsule& c = tool.parts()[0];
    TunnelCount n;
    for (int32_t v : slab.topVertices) {
        const double d = tool.signedDistance(x[v]);
        deepest = std::min(deepest, d);
        const double t = closestParameterOnSegment(x[v], c.a, c.b);
        const Vec3 q = c.a + t * (c.b - c.a);
        const double horizontal = std::hypot(x[v].x() - q.x(), x[v].y() - q.y());
        if (t > 0 && t < 1 && horizontal < c.radius && x[v].z() > q.z())
            ++n.over;
        else if (d < -1e-3)
            ++n.inside;
    }
    return n;
}

RunResult run(const Slab& slab, const RunSpec& spec) {
    using Clock = std::chrono::steady_clock;
    RunResult r;
    r.spec = spec;
    const bool post = spec.coupling == Coupling::PostSubstepInterp;
    const bool interp = spec.coupling != Coupling::InIteration;
    XpbdSettings xs;
    xs.substeps = post ? 1 : slab.substeps;
    xs.dt = post ? kFrame / slab.substeps : kFrame;
    xs.iterations = spec.iterations;
    xs.threads = 1;
    auto solver = XpbdSolver::create(*slab.mesh, slab.material, slab.fixed, xs);
    CollisionSettings cs;
    cs.method = spec.method;
    cs.circumsphere.updateThreshold = spec.delta;
    cs.circumsphere.energyScale = spec.energyScale;
    cs.circumsphere.curvatureThreshold = spec.curvatureThreshold;
    cs.circumsphere.safeAngle = spec.safeAngle;
    cs.safeConeOnly = spec.safeCone;
    cs.polygonMargin = 1e-3;
    auto col = CollisionSolver::create(CollisionSurfaceDesc::fromTetMesh(*slab.mesh, slab.invMass), cs);
    const double radius = spec.tool.radius;
    ToolShape tool = ToolShape::capsule(kHalfLen, radius);

    const double zStart = kTop + radius + 0.002, zPress = kTop + radius - spec.tool.depth;
    const int pressFrames = 12, holdFrames = 40,
              slideFrames = static_cast<int>(std::ceil(kSlide / (spec.speed * kFrame) - 1e-9)), endFrames = 10;
    struct Key {
        double x, z;
    };
    std::vector<Key> keys; // tool pose of each frame (device sample)
    for (int f = 1; f <= pressFrames; ++f)
        keys.push_back({kX0, zStart + (zPress - zStart) * f / pressFrames});
    for (int f = 0; f < holdFrames; ++f)
        keys.push_back({kX0, zPress});
    for (int f = 1; f <= slideFrames; ++f)
        keys.push_back({kX0 + std::min(kSlide, spec.speed * kFrame * f), zPress});
    for (int f = 0; f < endFrames; ++f)
        keys.push_back({kX0 + kSlide, zPress});

    ToolShape::Pose prev = toolPose(kX0, zStart), next = prev;
    tool.setPose(prev);
    double ct = 0;                         // collision seconds of the frame, accumulated by the hook
    double updates = 0, tracedUpdates = 0; // δ refreshes, all substeps
    if (!post)
        solver->setIterationHook([&](XpbdParticles& p, const XpbdIterationInfo& info) {
            if (info.velocityPass) {
                const auto c0 = Clock::now();
                col->endStep(p, 0);
                ct += std::chrono::duration<double>(Clock::now() - c0).count();
                return;
            }
            if (info.iteration == 0 && interp)
                tool.setPose(interpolatePose(prev, next, static_cast<double>(info.substep + 1) / info.substeps));
            const auto c0 = Clock::now();
            if (info.iteration == 0) {
                col->beginStep(p, 0, tool, info.h);
                updates += col->stats().factorUpdates;
            }
            col->iterate(p, 0, tool);
            ct += std::chrono::duration<double>(Clock::now() - c0).count();
        });
    std::vector<Vec3> last = solver->positions();
    double errSum = 0, holdSum = 0, slideSum = 0, colTime = 0, frameTime = 0, contactSum = 0;
    int errN = 0, holdN = 0, slideN = 0, steadyN = 0;
    double steadySum = 0;
    r.relErrMin = 1e300;
    r.relErrMax = -1e300;
    const int holdStart = pressFrames + 5, steadyStart = pressFrames + 20, slideStart = pressFrames + holdFrames;
    for (size_t f = 0; f < keys.size(); ++f) {
        next = toolPose(keys[f].x, keys[f].z);
        const auto t0 = Clock::now();
        ct = 0;
        if (!post) {
            if (!interp) tool.setPose(next);
            if (!solver->step().finite) r.finite = false;
        } else {
            for (int s = 1; s <= slab.substeps; ++s) {
                tool.setPose(interpolatePose(prev, next, static_cast<double>(s) / slab.substeps));
                if (!solver->step().finite) r.finite = false;
                std::vector<Vec3> x = solver->positions();
                const auto c0 = Clock::now();
                col->beginStep(x, tool, xs.dt);
                for (int k = 0; k < spec.iterations; ++k)
                    col->iterate(x, tool);
                ct += std::chrono::duration<double>(Clock::now() - c0).count();
                updates += col->stats().factorUpdates;
                if (col->stats().candidates == 0) continue;
                std::vector<Vec3> v = solver->velocities();
                collisionVelocityUpdate(solver->positions(), x, v);
                solver->setState(x, v);
            }
        }
        frameTime += std::chrono::duration<double>(Clock::now() - t0).count();
        colTime += ct;
        prev = next;
        const std::vector<Vec3>& x = solver->positions();
        for (const Vec3& p : x)
            if (!p.allFinite() || p.norm() > 1.0) r.finite = false; // diverged
        if (!r.finite) break;
        const TunnelCount tun = countTunnelled(x, slab, tool, r.deepestInside);
        r.tunnelledMax = std::max(r.tunnelledMax, tun.over + tun.inside);
        r.tunnelledFrames += (tun.over + tun.inside) > 0;
        r.overFrames += tun.over > 0;
        r.insideFrames += tun.inside > 0;
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
            const double rel = (d - radius) / radius;
            errSum += rel;
            ++errN;
            r.relErrMin = std::min(r.relErrMin, rel);
            r.relErrMax = std::max(r.relErrMax, rel);
            contactSum += cv.size();
            if (static_cast<int>(f) < slideStart) {
                holdSum += move;
                ++holdN;
                if (static_cast<int>(f) >= steadyStart) {
                    steadySum += move;
                    ++steadyN;
                }
            } else if (static_cast<int>(f) < slideStart + slideFrames) {
                slideSum += move;
                ++slideN;
            }
        }
        if (g_trace) {
            double d = 0, move = 0, maxMove = 0;
            const Capsule& c = tool.parts()[0];
            for (int32_t v : cv) {
                d += (x[v] - (c.a + closestParameterOnSegment(x[v], c.a, c.b) * (c.b - c.a))).norm();
                move += (x[v] - last[v]).norm();
            }
            for (size_t v = 0; v < x.size(); ++v)
                maxMove = std::max(maxMove, (x[v] - last[v]).norm());
            std::printf("  frame %3zu: contacts %3zu  mean dist %.4f  mean move %.2e  max node "
                        "move %.2e  candidates %d  contacts(last sweep) %d  factor updates %.0f\n",
                        f, cv.size(), cv.empty() ? 0.0 : d / cv.size(), cv.empty() ? 0.0 : move / cv.size(), maxMove,
                        col->stats().candidates, col->stats().contacts, updates - tracedUpdates);
            tracedUpdates = updates;
        }
        last = x;
    }
    const double frames = static_cast<double>(keys.size());
    r.relErrMean = errN ? errSum / errN : std::numeric_limits<double>::quiet_NaN();
    if (!errN) r.relErrMin = r.relErrMax = std::numeric_limits<double>::quiet_NaN();
    r.stabilityHold = holdN ? holdSum / holdN : 0;
    r.stabilitySlide = slideN ? slideSum / slideN : 0;
    r.stabilitySteady = steadyN ? steadySum / steadyN : 0;
    r.collisionMs = 1e3 * colTime / frames;
    r.frameMs = 1e3 * frameTime / frames;
    r.factorUpdatesPerFrame = updates / frames;
    r.contactVerticesMean = errN ? contactSum / errN : 0;
    return r;
}

std::string deltaName(double d) {
    if (!std::isfinite(d)) return "inf";
    return formatNumber(d);
}

std::string label(const RunSpec& s) {
    std::string l = std::string(s.tool.name) + " " + toString(s.method);
    if (s.method == CollisionMethod::Circumsphere) {
        l += " d=" + deltaName(s.delta);
        if (!s.safeCone) l += " no-cone";
    }
    return l;
}

void printHeader() {
    std::printf("\n%-34s %-11s %3s %5s %8s %8s %8s %9s %9s %9s %7s %7s %6s %5s %5s %5s %5s "
                "%9s\n",
                "tool method", "coupling", "it", "v", "relErr", "errMin", "errMax", "stab_hold", "stab_stdy",
                "stab_slid", "col_ms", "frm_ms", "upd", "tunFr", "over", "insd", "tunMx", "deepest");
}

void printRow(const RunResult& r) {
    std::printf("%-34s %-11s %3d %5.2f %+8.4f %+8.4f %+8.4f %9.3e %9.3e %9.3e %7.3f %7.2f %6.1f "
                "%5d %5d %5d %5d %+9.2e%s\n",
                label(r.spec).c_str(), couplingName(r.spec.coupling), r.spec.iterations, r.spec.speed, r.relErrMean,
                r.relErrMin, r.relErrMax, r.stabilityHold, r.stabilitySteady, r.stabilitySlide, r.collisionMs,
                r.frameMs, r.factorUpdatesPerFrame, r.tunnelledFrames, r.overFrames, r.insideFrames, r.tunnelledMax,
                r.deepestInside, r.finite ? "" : "  DIVERGED");
    std::fflush(stdout);
}

void writeRow(std::ofstream& o, const RunResult& r) {
    o << r.spec.tool.name << ',' << toString(r.spec.method) << ',' << couplingName(r.spec.coupling) << ','
      << deltaName(r.spec.delta) << ',' << r.spec.iterations << ',' << r.spec.speed << ',' << r.relErrMean << ','
      << r.relErrMin << ',' << r.relErrMax << ',' << r.stabilityHold << ',' << r.stabilitySteady << ','
      << r.stabilitySlide << ',' << r.collisionMs << ',' << r.frameMs << ',' << r.factorUpdatesPerFrame << ','
      << r.contactVerticesMean << ',' << r.tunnelledFrames << ',' << r.overFrames << ',' << r.insideFrames << ','
      << r.tunnelledMax << ',' << r.deepestInside << ',' << (r.finite ? 1 : 0) << ',' << (r.spec.safeCone ? 1 : 0)
      << '\n';
}

const char* kHeader =
    "tool,method,coupling,delta,iterations,speed_m_s,rel_err_mean,rel_err_min,rel_err_max,"
    "stability_hold_m,stability_steady_m,stability_slide_m,collision_ms,frame_ms,factor_updates_per_frame,"
    "contact_vertices_mean,tunnelled_frames,over_frames,inside_frames,tunnelled_max,"
    "deepest_inside_m,finite,safe_cone\n";

} // namespace

int main(int argc, char** argv) {
    std::filesystem::path outDir = "collision_out";
    bool quick = false;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "-h" || a == "--help") {
            std::fprintf(stderr, "usage: bench_collision [output-dir] [--quick]\n"
                                 "       bench_collision --trace [tool] [method] [iterations] "
                                 "[delta] [speed] [energy-scale]\n");
            return 0;
        }
        if (a == "--quick")
            quick = true;
        else if (a == "--trace")
            g_trace = true;
        else
            outDir = a;
    }
    if (g_trace) { // --trace [tool 0|1] [method 0..3] [iterations] [delta] [speed] [ς m] [h 1/m] [θ deg] [cone]
        const Slab slab = makeSlab();
        RunSpec s;
        auto arg = [&](int i, double def) { return argc > i ? std::atof(argv[i]) : def; };
        s.tool = arg(2, 0) == 0 ? kCylinder : kShaft;
        s.method = static_cast<CollisionMethod>(static_cast<int>(arg(3, 0)));
        s.iterations = static_cast<int>(arg(4, 5));
        s.delta = arg(5, CircumsphereParams{}.updateThreshold);
        s.speed = arg(6, 0.1);
        s.energyScale = arg(7, CircumsphereParams{}.energyScale);
        s.curvatureThreshold = arg(8, CircumsphereParams{}.curvatureThreshold);
        s.safeAngle = arg(9, CircumsphereParams{}.safeAngle * 180 / M_PI) * M_PI / 180;
        s.safeCone = arg(10, CollisionSettings{}.safeConeOnly ? 1 : 0) != 0;
        printHeader();
        printRow(run(slab, s));
        return 0;
    }
    std::filesystem::create_directories(outDir);
    const Slab slab = makeSlab();
    std::printf("slab %.0f x %.0f x %.0f mm: %zu tets, %zu nodes, %zu surface triangles; E = %.0f "
                "Pa, nu = %.2f; %d substeps per 1/60 s frame; tools: %s (r %.1f mm, pressed %.1f "
                "mm), %s (r %.1f mm, pressed %.1f mm); polygon margin 1 mm\n",
                kLx * 1e3, kLy * 1e3, kTop * 1e3, slab.mesh->tetCount(), slab.mesh->vertexCount(),
                slab.mesh->boundary().triangleCount(), slab.material.youngsModulus, slab.material.poissonRatio,
                slab.substeps, kCylinder.name, kCylinder.radius * 1e3, kCylinder.depth * 1e3, kShaft.name,
                kShaft.radius * 1e3, kShaft.depth * 1e3);
    const std::vector<int> iterations = quick ? std::vector<int>{1, 5} : std::vector<int>{1, 2, 3, 5, 10, 20};
    const std::vector<double> deltas =
        quick ? std::vector<double>{0, 0.3}
              : std::vector<double>{0, 0.1, 0.3, 0.7, 0.9, std::numeric_limits<double>::infinity()};
    const std::vector<CollisionMethod> methods = {CollisionMethod::Circumsphere, CollisionMethod::BoundingSphere,
                                                  CollisionMethod::PolygonFeatures, CollisionMethod::Polygon};
    const std::vector<Tool> tools = {kCylinder, kShaft};

    // 1. The comparison table: tool × method × iterations at 0.1 m/s, device-rate poses.
    std::printf("\n== comparison (slide 0.1 m/s, poses once per frame, contacts in the XPBD "
                "iteration) ==");
    printHeader();
    std::ofstream sweep(outDir / "collision_sweep.csv");
    sweep << kHeader;
    std::vector<RunResult> main;
    // Runs one case, prints its row, appends it to `into` and to the CSV.
    auto record = [&](const RunSpec& s, std::vector<RunResult>& into, std::ofstream& csv) {
        into.push_back(run(slab, s));
        printRow(into.back());
        writeRow(csv, into.back());
    };
    // The methods, and for reference the circumsphere without the safe-cone test.
    struct Variant {
        CollisionMethod method;
        bool safeCone;
    };
    std::vector<Variant> variants;
    for (CollisionMethod m : methods)
        variants.push_back({m, true});
    variants.push_back({CollisionMethod::Circumsphere, false});
    for (const Tool& t : tools)
        for (const Variant& v : variants)
            for (int k : iterations) {
                RunSpec s;
                s.tool = t;
                s.method = v.method;
                s.safeCone = v.safeCone;
                s.iterations = k;
                record(s, main, sweep);
            }
    // 2. δ sweep (circumsphere, 10 mm cylinder) at 2 and 5 iterations.
    std::printf("\n== update threshold (circumsphere, %s) ==", kCylinder.name);
    printHeader();
    std::vector<RunResult> deltaRuns;
    for (int k : quick ? std::vector<int>{5} : std::vector<int>{2, 5})
        for (double d : deltas) {
            RunSpec s;
            s.delta = d;
            s.iterations = k;
            record(s, deltaRuns, sweep);
        }
    // 3. Tunnelling: speeds 0.05–0.5 m/s, both tools, device-rate poses; at 0.5 m/s also the
    //    interpolated and the post-substep couplings for reference.
    std::printf("\n== tunnelling ==");
    printHeader();
    std::ofstream tunnel(outDir / "collision_tunnelling.csv");
    tunnel << kHeader;
    std::vector<RunResult> tunRuns;
    const std::vector<double> speeds = quick ? std::vector<double>{0.5} : std::vector<double>{0.05, 0.1, 0.25, 0.5};
    const std::vector<int> tunIts = quick ? std::vector<int>{1, 5} : std::vector<int>{1, 3, 5};
    for (const Tool& t : tools)
        for (double v : speeds)
            for (CollisionMethod m : methods)
                for (int k : tunIts) {
                    RunSpec s;
                    s.tool = t;
                    s.method = m;
                    s.iterations = k;
                    s.speed = v;
                    record(s, tunRuns, tunnel);
                }
    for (Coupling c : {Coupling::InIterationInterp, Coupling::PostSubstepInterp})
        for (CollisionMethod m : methods)
            for (int k : tunIts) {
                RunSpec s;
                s.tool = kShaft;
                s.method = m;
                s.iterations = k;
                s.speed = 0.5;
                s.coupling = c;
                record(s, tunRuns, tunnel);
            }
    if (!sweep || !tunnel) {
        std::fprintf(stderr, "bench_collision: cannot write CSV files in %s\n", outDir.string().c_str());
        return 1;
    }

    // Plots: the three criteria against iterations (per tool), and against δ.
    using viscera::bench::PlotSeries;
    using viscera::bench::PlotSpec;
    auto byIterations = [&](auto value) {
        std::vector<PlotSeries> out;
        for (const Tool& t : tools)
            for (const Variant& v : variants) {
                PlotSeries s;
                s.label = std::string(t.name) + " " + toString(v.method) + (v.safeCone ? "" : " (no safe cone)");
                s.markers = true;
                for (const RunResult& r : main)
                    if (r.spec.method == v.method && r.spec.tool.name == t.name && r.spec.safeCone == v.safeCone) {
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
    spec.title = "Stability: mean per-frame move of collided vertices, last 20 frames of the hold";
    plot("stability_steady_vs_iterations.png", spec,
         byIterations([](const RunResult& r) { return r.stabilitySteady; }));
    spec.title = "Stability: mean per-frame move of collided vertices, tool sliding 0.1 m/s";
    plot("stability_slide_vs_iterations.png", spec, byIterations([](const RunResult& r) { return r.stabilitySlide; }));
    spec.title = "Time: collision detection and response per frame (Fig. 5.13)";
    spec.yLabel = "ms per frame";
    plot("time_vs_iterations.png", spec, byIterations([](const RunResult& r) { return r.collisionMs; }));
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
                "*_vs_delta.png}\n",
                outDir.string().c_str());
    return 0;
}
