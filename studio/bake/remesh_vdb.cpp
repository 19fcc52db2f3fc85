// The OpenVDB half of the voxel remesh (bake/remesh.hpp, stages 1–4): level sets per part, the
// CSG combination, smoothing and the isosurface. The only translation unit that includes
// OpenVDB (it compiles slowly).
#include "bake/remesh.hpp"

#include "sim/util/error.hpp"
#include "sim/util/format.hpp"

#include <openvdb/openvdb.h>
#include <openvdb/tools/Composite.h>
#include <openvdb/tools/LevelSetFilter.h>
#include <openvdb/tools/LevelSetMeasure.h>
#include <openvdb/tools/MeshToVolume.h>
#include <openvdb/tools/VolumeToMesh.h>
#include <openvdb/util/NullInterrupter.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <unordered_map>
#include <utility>

namespace viscera::bake::detail {
namespace {

using Clock = std::chrono::steady_clock;

/// OpenVDB's cancellation hook: polled from its worker threads, so it only reads an atomic.
struct CancelInterrupter : openvdb::util::NullInterrupter {
    explicit CancelInterrupter(const std::atomic<bool>* flag) : cancel(flag) {}
    bool wasInterrupted(int = -1) override { return cancel && cancel->load(std::memory_order_relaxed); }
    const std::atomic<bool>* cancel;
};

void toVdb(const sim::TriMesh& m, std::vector<openvdb::Vec3s>& points, std::vector<openvdb::Vec3I>& tris) {
    points.clear();
    tris.clear();
    points.reserve(m.vertexCount());
    for (const sim::Vec3& p : m.positions())
        points.emplace_back(float(p.x()), float(p.y()), float(p.z()));
    tris.reserve(m.triangleCount());
    for (const sim::Tri& t : m.triangles())
        tris.emplace_back(openvdb::Index32(t[0]), openvdb::Index32(t[1]), openvdb::Index32(t[2]));
}

/// Triangles and quads of volumeToMesh as a surface: quads split along the shorter diagonal,
/// unreferenced points dropped, oriented so that the enclosed volume is positive.
sim::TriMesh fromVdb(const std::vector<openvdb::Vec3s>& points, const std::vector<openvdb::Vec3I>& tris,
                     const std::vector<openvdb::Vec4I>& quads, const std::string& label) {
    std::vector<sim::Tri> out;
    out.reserve(tris.size() + 2 * quads.size());
    auto add = [&](openvdb::Index32 a, openvdb::Index32 b, openvdb::Index32 c) {
        if (a != b && b != c && a != c) out.push_back({int32_t(a), int32_t(b), int32_t(c)});
    };
    for (const auto& t : tris)
        add(t[0], t[1], t[2]);
    for (const auto& q : quads) {
        const double d02 = (points[q[0]] - points[q[2]]).lengthSqr(), d13 = (points[q[1]] - points[q[3]]).lengthSqr();
        if (d02 <= d13) {
            add(q[0], q[1], q[2]);
            add(q[0], q[2], q[3]);
        } else {
            add(q[0], q[1], q[3]);
            add(q[1], q[2], q[3]);
        }
    }
    std::vector<int32_t> compact(points.size(), -1);
    std::vector<sim::Vec3> positions;
    for (sim::Tri& t : out)
        for (int32_t& v : t) {
            if (compact[v] < 0) {
                compact[v] = int32_t(positions.size());
                const auto& p = points[v];
                positions.emplace_back(p.x(), p.y(), p.z());
            }
            v = compact[v];
        }
    sim::TriMesh mesh = sim::TriMesh::fromArrays(std::move(positions), std::move(out), label);
    if (mesh.signedVolume() < 0) {
        std::vector<sim::Tri> flipped = mesh.triangles();
        for (sim::Tri& t : flipped)
            std::swap(t[1], t[2]);
        mesh = sim::TriMesh::fromArrays(mesh.positions(), std::move(flipped), label);
    }
    return mesh;
}

} // namespace

double largestHoleDiameter(const sim::TriMesh& mesh) {
    // Undirected edges used by one triangle only; a face orientation that flips between
    // neighbours is no hole (the level set does not depend on orientation).
    std::unordered_map<uint64_t, int> uses;
    auto key = [](int32_t a, int32_t b) {
        if (a > b) std::swap(a, b);
        return (uint64_t(uint32_t(a)) << 32) | uint32_t(b);
    };
    for (const sim::Tri& t : mesh.triangles())
        for (int k = 0; k < 3; ++k)
            ++uses[key(t[k], t[(k + 1) % 3])];
    // Boundary vertices grouped into loops by union-find over the boundary edges.
    std::unordered_map<int32_t, int32_t> parent;
    std::function<int32_t(int32_t)> root = [&](int32_t v) {
        while (parent[v] != v)
            v = parent[v] = parent[parent[v]];
        return v;
    };
    for (const auto& [k, n] : uses) {
        if (n != 1) continue;
        const auto a = int32_t(k >> 32), b = int32_t(k & 0xffffffffu);
        parent.try_emplace(a, a);
        parent.try_emplace(b, b);
        parent[root(a)] = root(b);
    }
    std::unordered_map<int32_t, std::pair<sim::Vec3, sim::Vec3>> box;
    for (const auto& [v, p] : parent) {
        const sim::Vec3& x = mesh.positions()[v];
        auto [it, fresh] = box.try_emplace(root(v), x, x);
        if (!fresh) {
            it->second.first = it->second.first.cwiseMin(x);
            it->second.second = it->second.second.cwiseMax(x);
        }
    }
    double most = 0;
    for (const auto& [r, b] : box)
        most = std::max(most, (b.second - b.first).norm());
    return most;
}

/// Holes up to this many voxels across may be closed over by the level set (then checked).
constexpr double kMaxClosedHoleVoxels = 3.0;

namespace {

/// The grid: one voxel size for every part, from the bounds of them all (checked against the
/// per-axis cap). Returns the voxel size.
double gridVoxelSize(const std::vector<RemeshPart>& parts, const RemeshParams& params, RemeshReport& report) {
    sim::Vec3 lo = sim::Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (const RemeshPart& part : parts) {
        const auto [a, b] = part.surface.bounds();
        lo = lo.cwiseMin(a);
        hi = hi.cwiseMax(b);
    }
    const sim::Vec3 extent = hi - lo;
    const double longest = extent.maxCoeff();
    if (!(longest > 0)) throw InputError(parts.front().name + ": the parts have no extent (all points coincide)");
    const double vs = params.voxelSize > 0 ? params.voxelSize : longest / params.voxelCount;
    for (int k = 0; k < 3; ++k) {
        const double n = std::ceil(extent[k] / vs) + 2 * std::ceil(params.bandVoxels);
        if (!(n <= params.maxVoxelsPerAxis))
            throw InputError("remesh: voxel size " + sim::formatNumber(vs * 1e3) + " mm gives " +
                             sim::formatNumber(std::ceil(n)) + " voxels along axis " + "xyz"[k] +
                             " of the parts' bounds (cap RemeshParams::maxVoxelsPerAxis = " +
                             std::to_string(params.maxVoxelsPerAxis) + ")");
        report.voxels[k] = int(n);
    }
    report.voxelSize = vs;
    return vs;
}

/// What the level sets of all parts share: the grid, the band, cancellation, and the buffers the
/// current part's surface is converted into (reused from part to part).
struct LevelSetContext {
    const openvdb::math::Transform& xform;
    double voxelSize;
    float band;
    double fillOpenings; ///< RemeshParams::fillOpenings, m
    CancelInterrupter& interrupter;
    const std::atomic<bool>* cancel;
    std::vector<openvdb::Vec3s> points;
    std::vector<openvdb::Vec3I> tris;
};

/// The level set of a part that is closed or has small holes, or null when it leaked (then the
/// part is to be thickened like an open one).
openvdb::FloatGrid::Ptr closedLevelSet(const RemeshPart& part, double hole, LevelSetContext& ctx,
                                       RemeshReport& report) {
    // Closed, or with holes of at most three voxels, which OpenVDB's sign flood often
    // closes over; whether it did is checked: the level set must hold at least half the
    // part's enclosed volume, else the part is thickened like an open one.
    openvdb::FloatGrid::Ptr grid =
        openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(ctx.interrupter, ctx.xform, ctx.points, ctx.tris, ctx.band);
    checkCancel(ctx.cancel);
    const double inside = openvdb::tools::levelSetVolume(*grid);
    const double enclosed = std::abs(part.surface.signedVolume());
    if (!(inside >= 0.5 * enclosed)) {
        ++report.leakedParts;
        return nullptr;
    }
    report.sourceVolume += enclosed;
    if (hole > 0) ++report.closedHoles;
    return grid;
}

/// The level set of an open part, thickened into a closed shell.
openvdb::FloatGrid::Ptr shellLevelSet(const RemeshPart& part, LevelSetContext& ctx, RemeshReport& report) {
    // No inside: thicken the open surface into a closed shell 1.5 voxels thick (the
    // unsigned distance at 0.75 voxels), then take the shell's level set.
    ++report.openParts;
    const std::vector<openvdb::Vec4I> noQuads;
    auto udf = openvdb::tools::meshToUnsignedDistanceField<openvdb::FloatGrid>(ctx.interrupter, ctx.xform, ctx.points,
                                                                               ctx.tris, noQuads, ctx.band);
    checkCancel(ctx.cancel);
    std::vector<openvdb::Vec3s> shellPoints;
    std::vector<openvdb::Vec3I> shellTris;
    std::vector<openvdb::Vec4I> shellQuads;
    openvdb::tools::volumeToMesh(*udf, shellPoints, shellTris, shellQuads, 0.75 * ctx.voxelSize, 0.0);
    if (shellTris.empty() && shellQuads.empty())
        throw InputError(part.name + ": the open part is thinner than the voxel grid resolves (voxel size " +
                         sim::formatNumber(ctx.voxelSize * 1e3) + " mm)");
    return openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(ctx.interrupter, ctx.xform, shellPoints, shellTris,
                                                              shellQuads, ctx.band);
}

/// One part's level set: closed (holes included, if they close; openings up to fillOpenings capped
/// first) or thickened.
openvdb::FloatGrid::Ptr partLevelSet(const RemeshPart& part, LevelSetContext& ctx, RemeshReport& report) {
    openvdb::FloatGrid::Ptr grid;
    const double hole = part.surface.isClosedOriented() ? 0.0 : largestHoleDiameter(part.surface);
    if (hole > 0 && hole <= ctx.fillOpenings) {
        const RemeshPart filled{part.name, capOpenings(part.surface, part.name), part.op, {}};
        toVdb(filled.surface, ctx.points, ctx.tris);
        grid = closedLevelSet(filled, 0.0, ctx, report);
        checkCancel(ctx.cancel);
        if (grid) {
            ++report.filledParts;
            return grid;
        }
    }
    toVdb(part.surface, ctx.points, ctx.tris);
    const bool thicken = hole >= kMaxClosedHoleVoxels * ctx.voxelSize;
    if (!thicken) grid = closedLevelSet(part, hole, ctx, report);
    if (!grid) grid = shellLevelSet(part, ctx, report);
    checkCancel(ctx.cancel);
    return grid;
}

/// Applies a part's operation to the combination (the first part starts it).
void combine(openvdb::FloatGrid::Ptr& combined, const openvdb::FloatGrid::Ptr& grid, CsgOp op) {
    if (!combined) {
        combined = grid;
        return;
    }
    switch (op) {
    case CsgOp::Union:
        openvdb::tools::csgUnion(*combined, *grid);
        break;
    case CsgOp::Difference:
        openvdb::tools::csgDifference(*combined, *grid);
        break;
    case CsgOp::Intersection:
        openvdb::tools::csgIntersection(*combined, *grid);
        break;
    }
}

/// The zero isosurface of the combined level set, within the triangle cap.
sim::TriMesh isosurface(const openvdb::FloatGrid& combined, const RemeshParams& params, double vs,
                        RemeshReport& report) {
    const auto t1 = Clock::now();
    std::vector<openvdb::Vec3s> isoPoints;
    std::vector<openvdb::Vec3I> isoTris;
    std::vector<openvdb::Vec4I> isoQuads;
    openvdb::tools::volumeToMesh(combined, isoPoints, isoTris, isoQuads, 0.0, 0.0);
    const size_t triangles = isoTris.size() + 2 * isoQuads.size();
    if (triangles == 0)
        throw InputError("remesh: the combined volume is empty (the operations leave nothing inside at voxel size " +
                         sim::formatNumber(vs * 1e3) + " mm)");
    if (triangles > params.maxTriangles)
        throw InputError("remesh: the isosurface has " + std::to_string(triangles) +
                         " triangles (cap RemeshParams::maxTriangles = " + std::to_string(params.maxTriangles) +
                         "); use a larger voxel size");
    sim::TriMesh iso = fromVdb(isoPoints, isoTris, isoQuads, "remesh isosurface");
    report.isoTriangles = iso.triangleCount();
    report.isosurfaceSeconds = secondsSince(t1);
    return iso;
}

} // namespace

sim::TriMesh combinedIsosurface(const std::vector<RemeshPart>& parts, const RemeshParams& params,
                                const RemeshProgress& progress, const std::atomic<bool>* cancel, RemeshReport& report) {
    openvdb::initialize();
    auto stage = [&](const std::string& name, double fraction) { reportStage(progress, cancel, name, fraction); };
    // The grid: one voxel size for every part, from the bounds of them all.
    const double vs = gridVoxelSize(parts, params, report);
    const auto xform = openvdb::math::Transform::createLinearTransform(vs);
    CancelInterrupter interrupter(cancel);
    LevelSetContext ctx{*xform, vs, float(params.bandVoxels), params.fillOpenings, interrupter, cancel, {}, {}};

    const auto t0 = Clock::now();
    openvdb::FloatGrid::Ptr combined;
    const double levelSetShare = 0.6;
    for (size_t i = 0; i < parts.size(); ++i) {
        const RemeshPart& part = parts[i];
        stage("level set " + std::to_string(i + 1) + "/" + std::to_string(parts.size()) + ": " + part.name,
              levelSetShare * double(i) / double(parts.size()));
        combine(combined, partLevelSet(part, ctx, report), part.op);
    }
    if (params.smoothingIterations > 0) {
        openvdb::tools::LevelSetFilter<openvdb::FloatGrid> filter(*combined);
        for (int i = 0; i < params.smoothingIterations; ++i) {
            stage("smoothing", levelSetShare + 0.1 * double(i) / params.smoothingIterations);
            filter.meanCurvature();
        }
    }
    report.activeVoxels = size_t(combined->activeVoxelCount());
    report.levelSetSeconds = secondsSince(t0);

    stage("isosurface", levelSetShare + 0.1);
    return isosurface(*combined, params, vs, report);
}

} // namespace viscera::bake::detail
