// The CGAL half of the voxel remesh (bake/remesh.hpp, stages 5–6): parameter rules, isotropic
// remeshing with hard edges, the checks and figures of the result, and the OBJ writer.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized" // Boost.Graph in CGAL's feature detection
#endif

#include "bake/remesh.hpp"
#include "bake/surface_check.hpp"
#include "bake/uv_transfer.hpp"

#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"
#include "sim/util/format.hpp"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/border.h>
#include <CGAL/Polygon_mesh_processing/detect_features.h>
#include <CGAL/Polygon_mesh_processing/remesh.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/triangulate_hole.h>
#include <CGAL/Surface_mesh.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <string>
#include <vector>

namespace viscera::bake {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using SurfaceMesh = CGAL::Surface_mesh<K::Point_3>;
namespace PMP = CGAL::Polygon_mesh_processing;
using Clock = std::chrono::steady_clock;
using detail::secondsSince;

void require(bool ok, const std::string& field, const std::string& rule) {
    if (!ok) throw std::invalid_argument("bake::voxelRemesh(): RemeshParams::" + field + " " + rule);
}

void validate(const RemeshParams& p) {
    require(std::isfinite(p.voxelSize) && p.voxelSize >= 0, "voxelSize", "must be finite and >= 0");
    require(p.maxVoxelsPerAxis >= 8 && p.maxVoxelsPerAxis <= 65536, "maxVoxelsPerAxis", "must be in [8, 65536]");
    require(p.voxelCount >= 8 && p.voxelCount + 2 * std::ceil(p.bandVoxels) <= p.maxVoxelsPerAxis, "voxelCount",
            "must be in [8, maxVoxelsPerAxis - 2 bandVoxels] (the band pads the grid on each side)");
    require(std::isfinite(p.bandVoxels) && p.bandVoxels >= 3 && p.bandVoxels <= 16, "bandVoxels", "must be in [3, 16]");
    require(p.smoothingIterations >= 0 && p.smoothingIterations <= 100, "smoothingIterations", "must be in [0, 100]");
    require(std::isfinite(p.targetEdgeLength) && p.targetEdgeLength >= 0, "targetEdgeLength",
            "must be finite and >= 0");
    require(p.remeshIterations >= 0 && p.remeshIterations <= 20, "remeshIterations", "must be in [0, 20]");
    require(std::isfinite(p.fillOpenings) && p.fillOpenings >= 0 && p.fillOpenings <= 1, "fillOpenings",
            "must be in [0, 1] m");
    require(std::isfinite(p.featureAngleDeg) && p.featureAngleDeg > 0 && p.featureAngleDeg <= 180, "featureAngleDeg",
            "must be in (0, 180]");
    require(p.maxTriangles >= 4, "maxTriangles", "must be at least 4");
    require(p.seamCut.snapFraction >= 0 && p.seamCut.snapFraction <= 0.45, "seamCut.snapFraction",
            "must be in [0, 0.45]");
    require(p.seamCut.refineRounds >= 0 && p.seamCut.refineRounds <= 8, "seamCut.refineRounds", "must be in [0, 8]");
}

/// Isotropic remeshing of `sm` to `edge` in one call (each call would rebuild its projection tree
/// from the current mesh, so iterations would project onto the previous output and drift), with
/// the edges over the feature angle and `hard` (vertex pairs) held as constraints: they may be
/// split or collapsed along themselves, never flipped or moved off their line. Returns the
/// feature edges found.
size_t remeshWithHardEdges(SurfaceMesh& sm, double edge, const RemeshParams& params,
                           const std::vector<std::array<int32_t, 2>>& hard,
                           SurfaceMesh::Property_map<SurfaceMesh::Edge_index, bool>& ecm, bool protect = false) {
    ecm = sm.add_property_map<SurfaceMesh::Edge_index, bool>("e:hard", false).first;
    PMP::detect_sharp_edges(sm, params.featureAngleDeg, ecm);
    size_t features = 0;
    for (auto e : sm.edges())
        features += ecm[e] ? 1 : 0;
    for (const auto& [a, b] : hard) {
        const auto h = sm.halfedge(SurfaceMesh::Vertex_index(uint32_t(a)), SurfaceMesh::Vertex_index(uint32_t(b)));
        if (h != SurfaceMesh::null_halfedge()) ecm[sm.edge(h)] = true;
    }
    PMP::isotropic_remeshing(faces(sm), edge, sm,
                             PMP::parameters::number_of_iterations(unsigned(params.remeshIterations))
                                 .edge_is_constrained_map(ecm)
                                 .protect_constraints(protect));
    if (sm.number_of_faces() > params.maxTriangles)
        throw InputError("remesh: remeshing gives " + std::to_string(sm.number_of_faces()) +
                         " triangles (cap RemeshParams::maxTriangles = " + std::to_string(params.maxTriangles) +
                         "); use a longer target edge length");
    return features;
}

/// `what` names the surface in the refusal ("remesh: the isosurface is not manifold at triangle 7").
SurfaceMesh toSurfaceMesh(const sim::TriMesh& m, const std::string& what = "remesh: the isosurface") {
    SurfaceMesh sm;
    std::vector<SurfaceMesh::Vertex_index> v;
    v.reserve(m.vertexCount());
    for (const sim::Vec3& p : m.positions())
        v.push_back(sm.add_vertex(K::Point_3(p.x(), p.y(), p.z())));
    for (size_t t = 0; t < m.triangleCount(); ++t) {
        const sim::Tri& tri = m.triangles()[t];
        if (sm.add_face(v[tri[0]], v[tri[1]], v[tri[2]]) == SurfaceMesh::null_face())
            throw InputError(what + " is not manifold at triangle " + std::to_string(t));
    }
    return sm;
}

Eigen::Vector3d point(const SurfaceMesh& sm, SurfaceMesh::Vertex_index v) {
    const K::Point_3& p = sm.point(v);
    return {p.x(), p.y(), p.z()};
}

Eigen::Vector3d centroid(const SurfaceMesh& sm, SurfaceMesh::Face_index f) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (auto v : vertices_around_face(sm.halfedge(f), sm))
        c += point(sm, v) / 3.0;
    return c;
}

sim::TriMesh toTriMesh(SurfaceMesh& sm) {
    sm.collect_garbage();
    std::vector<sim::Vec3> positions;
    positions.reserve(sm.number_of_vertices());
    for (auto v : sm.vertices()) {
        const K::Point_3& p = sm.point(v);
        positions.emplace_back(p.x(), p.y(), p.z());
    }
    std::vector<sim::Tri> tris;
    tris.reserve(sm.number_of_faces());
    for (auto f : sm.faces()) {
        sim::Tri t{};
        int k = 0;
        for (auto v : CGAL::vertices_around_face(sm.halfedge(f), sm))
            if (k < 3) t[k++] = int32_t(v.idx());
        tris.push_back(t);
    }
    return sim::TriMesh::fromArrays(std::move(positions), std::move(tris), "remesh result");
}

} // namespace

std::string_view csgOpName(CsgOp op) {
    switch (op) {
    case CsgOp::Union:
        return "union";
    case CsgOp::Difference:
        return "difference";
    case CsgOp::Intersection:
        return "intersection";
    }
    return "union";
}

namespace {

/// The seam-cut surface remeshed with its chart borders held (protected: neither split nor
/// collapsed, so no border is straightened over a bend), its seam edges found again. Where that
/// remesh makes triangles intersect (held short edges in a thin region), the cut surface is kept
/// as it is (report.seamCut.remeshKept false), cut again without snapping: only splits of
/// `uncut`'s triangles in their planes, which cannot make triangles intersect.
void remeshCut(const UvSource& source, const sim::TriMesh& uncut, const RemeshParams& params, RemeshReport& report,
               UvMesh& cut) {
    SurfaceMesh sm = toSurfaceMesh(cut.mesh);
    SurfaceMesh::Property_map<SurfaceMesh::Edge_index, bool> ecm;
    remeshWithHardEdges(sm, report.targetEdgeLength, params, cut.chartBorders, ecm, true);
    sm.collect_garbage();
    std::vector<std::pair<SurfaceMesh::Face_index, SurfaceMesh::Face_index>> pairs;
    PMP::self_intersections(sm, std::back_inserter(pairs));
    report.seamCut.remeshKept = pairs.empty();
    if (!pairs.empty()) {
        SeamCutParams plain = params.seamCut;
        plain.snapFraction = 0;
        cut = cutAlongSeams(source, uncut, plain, &report.seamCut);
        report.seamCut.remeshKept = false;
        return;
    }
    cut.mesh = toTriMesh(sm);
    cut.seamEdges.clear();
    for (auto e : sm.edges()) // the held edges that lie on a seam or between two islands
        if (ecm[e] && !sm.is_border(e)) {
            const auto h = sm.halfedge(e);
            const auto a = sm.source(h), b = sm.target(h);
            if (isSeamEdge(source, point(sm, a), point(sm, b), centroid(sm, sm.face(h)),
                           centroid(sm, sm.face(sm.opposite(h)))))
                cut.seamEdges.push_back({int32_t(a.idx()), int32_t(b.idx())});
        }
}

} // namespace

RemeshResult voxelRemesh(const std::vector<RemeshPart>& parts, const RemeshParams& params,
                         const RemeshProgress& progress, const std::atomic<bool>* cancel) {
    validate(params);
    if (parts.empty()) throw std::invalid_argument("bake::voxelRemesh(): no parts");
    for (const RemeshPart& part : parts)
        if (part.surface.triangleCount() == 0) throw InputError(part.name + ": the part has no triangles");
    auto stage = [&](const std::string& name, double fraction) {
        detail::reportStage(progress, cancel, name, fraction);
    };
    RemeshReport report;
    const sim::TriMesh iso = detail::combinedIsosurface(parts, params, progress, cancel, report);
    report.isoVolume = iso.signedVolume();

    const double vs = report.voxelSize;
    report.targetEdgeLength = params.targetEdgeLength > 0 ? std::max(params.targetEdgeLength, 0.5 * vs) : 1.5 * vs;
    const auto t0 = Clock::now();
    SurfaceMesh sm = toSurfaceMesh(iso);
    if (params.remeshIterations > 0) {
        stage("remeshing (" + std::to_string(params.remeshIterations) + " iterations)", 0.72);
        SurfaceMesh::Property_map<SurfaceMesh::Edge_index, bool> ecm;
        report.featureEdges = remeshWithHardEdges(sm, report.targetEdgeLength, params, {}, ecm);
    }
    sim::TriMesh result = toTriMesh(sm);
    report.remeshSeconds = secondsSince(t0);

    RemeshResult out;
    const bool withUv =
        params.transferUv && std::all_of(parts.begin(), parts.end(), [](const RemeshPart& p) { return !p.uv.empty(); });
    if (withUv) {
        // [A §3.3.4, Algorithm 1]: cut along the seams, remesh with the chart borders held, transfer.
        stage("seam cut", 0.8);
        const auto tu = Clock::now();
        const UvSource source(parts);
        UvMesh cut = cutAlongSeams(source, result, params.seamCut, &report.seamCut);
        if (params.remeshIterations > 0) {
            stage("remeshing along the seams", 0.84);
            remeshCut(source, result, params, report, cut);
        }
        sm = toSurfaceMesh(cut.mesh);
        out.uncut = std::move(result);
        result = std::move(cut.mesh);
        out.seamEdges = std::move(cut.seamEdges);
        out.uv = transferUv(source, result, UvTransferMethod::SeamCutting);
        report.uvTransferred = true;
        report.seamEdges = out.seamEdges.size();
        report.uvSeconds = secondsSince(tu);
    }

    stage("checks", 0.93);
    const auto t1 = Clock::now();
    report.vertices = result.vertexCount();
    report.triangles = result.triangleCount();
    std::string topology;
    try {
        detail::checkInputSurface("remesh result", result);
        report.closed = report.manifold = true;
    } catch (const InputError& e) {
        topology = e.what();
    }
    std::vector<std::pair<SurfaceMesh::Face_index, SurfaceMesh::Face_index>> pairs;
    PMP::self_intersections(sm, std::back_inserter(pairs));
    report.selfIntersections = pairs.size();
    // Distance from the result to the source surfaces, at its vertices and face centroids.
    std::vector<K::Triangle_3> source;
    for (const RemeshPart& part : parts)
        for (const sim::Tri& t : part.surface.triangles()) {
            const auto& p = part.surface.positions();
            auto pt = [&](int32_t i) { return K::Point_3(p[i].x(), p[i].y(), p[i].z()); };
            const K::Triangle_3 tri(pt(t[0]), pt(t[1]), pt(t[2]));
            if (!tri.is_degenerate()) source.push_back(tri);
        }
    if (source.empty()) throw InputError(parts.front().name + ": every triangle of the parts is degenerate");
    using Primitive = CGAL::AABB_triangle_primitive<K, std::vector<K::Triangle_3>::const_iterator>;
    CGAL::AABB_tree<CGAL::AABB_traits<K, Primitive>> tree(source.cbegin(), source.cend());
    tree.accelerate_distance_queries();
    double sum = 0, most = 0;
    size_t samples = 0;
    auto sample = [&](const sim::Vec3& q) {
        const double d = std::sqrt(tree.squared_distance(K::Point_3(q.x(), q.y(), q.z())));
        sum += d;
        most = std::max(most, d);
        ++samples;
    };
    for (const sim::Vec3& q : result.positions())
        sample(q);
    for (const sim::Tri& t : result.triangles())
        sample((result.positions()[t[0]] + result.positions()[t[1]] + result.positions()[t[2]]) / 3.0);
    report.distanceMeanMm = samples ? 1e3 * sum / double(samples) : 0;
    report.distanceMaxMm = 1e3 * most;
    report.volume = result.signedVolume();
    report.volumeChangeFromIso = report.isoVolume != 0 ? (report.volume - report.isoVolume) / report.isoVolume : 0;
    report.checkSeconds = secondsSince(t1);
    if (!topology.empty()) throw InputError(topology + " (try more smoothing or a shorter target edge length)");
    if (report.selfIntersections > 0)
        throw InputError("remesh result: " + std::to_string(report.selfIntersections) +
                         " pair(s) of triangles intersect (try a shorter target edge length or more smoothing)");
    stage("done", 1.0);
    out.mesh = std::move(result);
    out.report = report;
    return out;
}

namespace detail {

void reportStage(const RemeshProgress& progress, const std::atomic<bool>* cancel, const std::string& stage,
                 double fraction) {
    checkCancel(cancel);
    if (progress && !progress(stage, fraction)) throw RemeshCancelled();
}

sim::TriMesh capOpenings(const sim::TriMesh& mesh, const std::string& name) {
    SurfaceMesh sm = toSurfaceMesh(mesh, name + ": cannot fill its openings: the surface");
    std::vector<SurfaceMesh::Halfedge_index> cycles;
    PMP::extract_boundary_cycles(sm, std::back_inserter(cycles));
    for (SurfaceMesh::Halfedge_index h : cycles) {
        std::vector<SurfaceMesh::Face_index> added;
        PMP::triangulate_hole(sm, h, std::back_inserter(added));
        if (added.empty()) throw InputError(name + ": an opening could not be filled (CGAL hole triangulation)");
    }
    return toTriMesh(sm);
}

void checkCancel(const std::atomic<bool>* cancel) {
    if (cancel && cancel->load()) throw RemeshCancelled();
}

double secondsSince(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

} // namespace detail

void writeObj(const std::string& path, const sim::TriMesh& mesh) {
    std::string text = "# viscera-studio remesh: " + std::to_string(mesh.vertexCount()) + " vertices, " +
                       std::to_string(mesh.triangleCount()) + " triangles, metres\n";
    char line[128];
    for (const sim::Vec3& p : mesh.positions()) {
        std::snprintf(line, sizeof line, "v %.9g %.9g %.9g\n", p.x(), p.y(), p.z());
        text += line;
    }
    for (const sim::Tri& t : mesh.triangles()) {
        std::snprintf(line, sizeof line, "f %d %d %d\n", t[0] + 1, t[1] + 1, t[2] + 1);
        text += line;
    }
    writeFileAtomic(path, text);
}

} // namespace viscera::bake
