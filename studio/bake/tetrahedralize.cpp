// The only translation unit of viscera::bake that includes CGAL (it compiles slowly): the surface
// checks, the polyhedral domain, Mesh_3 refinement and optimizers, and the export to sim::TetMesh.
//
// Boost.Graph code that CGAL's feature detection instantiates trips GCC's -Wmaybe-uninitialized
// (boost::detail::edge_desc_impl copies default-constructed, unused endpoints). The pragma comes
// before every include because GCC matches it against the location of the warning.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif

#include "bake/tetrahedralize.hpp"
#include "bake/surface_check.hpp"

#include "sim/util/error.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Mesh_complex_3_in_triangulation_3.h>
#include <CGAL/Mesh_criteria_3.h>
#include <CGAL/Mesh_triangulation_3.h>
#include <CGAL/Polygon_mesh_processing/detect_features.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polyhedral_mesh_domain_with_features_3.h>
#include <CGAL/Random.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/exceptions.h>
#include <CGAL/make_mesh_3.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace viscera::bake {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using SurfaceMesh = CGAL::Surface_mesh<K::Point_3>;
using Domain = CGAL::Polyhedral_mesh_domain_with_features_3<K, SurfaceMesh>;
using Tr = CGAL::Mesh_triangulation_3<Domain, CGAL::Default, CGAL::Sequential_tag>::type;
using C3t3 = CGAL::Mesh_complex_3_in_triangulation_3<Tr, Domain::Corner_index, Domain::Curve_index>;
using Criteria = CGAL::Mesh_criteria_3<Tr>;
namespace PMP = CGAL::Polygon_mesh_processing;

/// Volume of a regular tetrahedron of circumradius 1 (8·sqrt(3)/27).
constexpr double kRegularTetVolumePerR3 = 0.5132002392796673;

[[noreturn]] void fail(const std::string& label, const std::string& message) {
    throw InputError(label + ": " + message);
}

void requireParam(bool ok, const char* field, double value, const char* rule) {
    if (!ok)
        throw std::invalid_argument(std::string("bake::tetrahedralize(): MeshingParams::") + field + " is " +
                                    std::to_string(value) + " (" + rule + ")");
}

void validateParams(const MeshingParams& p) {
    requireParam(std::isfinite(p.facetAngleDeg) && p.facetAngleDeg > 0 && p.facetAngleDeg <= 30, "facetAngleDeg",
                 p.facetAngleDeg, "must be in (0, 30]");
    const std::pair<const char*, double> sizes[] = {{"facetSize", p.facetSize},
                                                    {"facetDistance", p.facetDistance},
                                                    {"cellSize", p.cellSize},
                                                    {"edgeSize", p.edgeSize}};
    for (const auto& [name, v] : sizes)
        requireParam(std::isfinite(v) && v >= 0, name, v, "must be finite and >= 0; 0 = automatic");
    requireParam(std::isfinite(p.cellRadiusEdgeRatio) && p.cellRadiusEdgeRatio >= 2, "cellRadiusEdgeRatio",
                 p.cellRadiusEdgeRatio, "must be >= 2");
    requireParam(std::isfinite(p.featureAngleDeg) && p.featureAngleDeg < 180, "featureAngleDeg", p.featureAngleDeg,
                 "must be below 180; <= 0 disables sharp features");
    requireParam(p.smoothingMaxIterations >= 0, "smoothingMaxIterations", p.smoothingMaxIterations,
                 "must be >= 0; 0 = until converged");
    requireParam(p.maxEstimatedTets > 0, "maxEstimatedTets", static_cast<double>(p.maxEstimatedTets), "must be > 0");
}

/// Builds the CGAL surface from the referenced vertices; checks degenerate triangles and
/// self-intersections (the indices in messages are those of the input TriMesh).
SurfaceMesh buildSurfaceMesh(const std::string& label, const sim::TriMesh& surface) {
    SurfaceMesh sm;
    std::vector<SurfaceMesh::Vertex_index> vmap(surface.vertexCount());
    std::vector<char> used(surface.vertexCount(), 0);
    for (const sim::Tri& t : surface.triangles())
        for (int32_t v : t)
            used[v] = 1;
    for (size_t v = 0; v < surface.vertexCount(); ++v)
        if (used[v]) {
            const sim::Vec3& p = surface.positions()[v];
            vmap[v] = sm.add_vertex(K::Point_3(p.x(), p.y(), p.z()));
        }
    const auto& tris = surface.triangles();
    for (size_t t = 0; t < tris.size(); ++t) {
        const auto& a = sm.point(vmap[tris[t][0]]);
        const auto& b = sm.point(vmap[tris[t][1]]);
        const auto& c = sm.point(vmap[tris[t][2]]);
        if (CGAL::collinear(a, b, c)) fail(label, "triangle " + std::to_string(t) + " is degenerate (zero area)");
        if (sm.add_face(vmap[tris[t][0]], vmap[tris[t][1]], vmap[tris[t][2]]) == SurfaceMesh::null_face())
            fail(label, "surface is not manifold at triangle " + std::to_string(t));
    }
    std::vector<std::pair<SurfaceMesh::Face_index, SurfaceMesh::Face_index>> pairs;
    PMP::self_intersections(sm, std::back_inserter(pairs));
    if (!pairs.empty()) {
        // Name the pair with the smallest triangle indices (deterministic).
        auto ordered = [](const auto& pair) {
            const size_t a = pair.first, b = pair.second;
            return std::pair<size_t, size_t>(std::min(a, b), std::max(a, b));
        };
        std::pair<size_t, size_t> first = ordered(pairs.front());
        for (const auto& pair : pairs)
            first = std::min(first, ordered(pair));
        fail(label, "surface self-intersects: triangles " + std::to_string(first.first) + " and " +
                        std::to_string(first.second) + " intersect (" + std::to_string(pairs.size()) +
                        " intersecting pair(s) in all)");
    }
    return sm;
}

/// Reseeds CGAL's default random generator (thread-local) for the duration of a call.
class DefaultRandomScope {
public:
    explicit DefaultRandomScope(uint32_t seed) : m_saved(CGAL::get_default_random()) {
        CGAL::get_default_random() = CGAL::Random(seed);
    }
    ~DefaultRandomScope() { CGAL::get_default_random() = m_saved; }
    DefaultRandomScope(const DefaultRandomScope&) = delete;
    DefaultRandomScope& operator=(const DefaultRandomScope&) = delete;

private:
    CGAL::Random m_saved;
};

/// Reports stage starts with an overall fraction from fixed stage weights.
class Progress {
public:
    Progress(ProgressCallback cb, const MeshingParams& p) : m_cb(std::move(cb)) {
        const std::pair<MeshingStage, double> all[] = {{MeshingStage::CheckSurface, 0.03},
                                                       {MeshingStage::BuildDomain, 0.05},
                                                       {MeshingStage::Refine, 0.50},
                                                       {MeshingStage::Odt, p.odt ? 0.10 : 0.0},
                                                       {MeshingStage::Lloyd, p.lloyd ? 0.10 : 0.0},
                                                       {MeshingStage::Perturb, p.perturb ? 0.15 : 0.0},
                                                       {MeshingStage::Exude, p.exude ? 0.10 : 0.0},
                                                       {MeshingStage::Export, 0.05}};
        double total = 0;
        for (const auto& [s, w] : all)
            total += w;
        double acc = 0;
        for (const auto& [s, w] : all) {
            m_start[static_cast<size_t>(s)] = acc / total;
            acc += w;
        }
    }
    void begin(MeshingStage s) const {
        if (m_cb) m_cb(s, m_start[static_cast<size_t>(s)]);
    }
    void done() const {
        if (m_cb) m_cb(MeshingStage::Export, 1.0);
    }

private:
    ProgressCallback m_cb;
    std::array<double, 8> m_start{};
};

double secondsSince(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// The parameters with their automatic values filled in (from the surface's bounding-box
/// diagonal); checks that the surface encloses volume and that the sizes give a feasible count.
MeshingParams resolveParams(const std::string& label, const sim::TriMesh& surface, const MeshingParams& params,
                            MeshingReport& report) {
    sim::Vec3 lo = sim::Vec3::Constant(HUGE_VAL), hi = sim::Vec3::Constant(-HUGE_VAL);
    for (const sim::Tri& t : surface.triangles())
        for (int32_t v : t) {
            lo = lo.cwiseMin(surface.positions()[v]);
            hi = hi.cwiseMax(surface.positions()[v]);
        }
    const double diagonal = (hi - lo).norm();
    MeshingParams p = params;
    if (p.facetSize == 0) p.facetSize = diagonal / 20;
    if (p.facetDistance == 0) p.facetDistance = p.facetSize / 10;
    if (p.cellSize == 0) p.cellSize = p.facetSize;
    if (p.edgeSize == 0) p.edgeSize = p.facetSize;
    report.resolved = p;
    if (!(report.surfaceVolume > 1e-12 * diagonal * diagonal * diagonal))
        fail(label, "surface encloses no volume (" + std::to_string(report.surfaceVolume) + " m^3)");
    const double s = std::min(p.cellSize, p.facetSize);
    const double estimate = report.surfaceVolume / (kRegularTetVolumePerR3 * s * s * s);
    if (estimate > static_cast<double>(p.maxEstimatedTets))
        fail(label, "sizes too small for the volume: cellSize " + std::to_string(p.cellSize) + " m and facetSize " +
                        std::to_string(p.facetSize) + " m give about " +
                        std::to_string(static_cast<long long>(estimate)) +
                        " tets (limit MeshingParams::maxEstimatedTets = " + std::to_string(p.maxEstimatedTets) + ")");
    return p;
}

/// Counts the edges sharper than `featureAngleDeg` (the property map is removed again).
size_t countSharpEdges(SurfaceMesh& sm, double featureAngleDeg) {
    size_t count = 0;
    auto sharp = sm.add_property_map<SurfaceMesh::Edge_index, bool>("e:viscera_sharp", false).first;
    PMP::detect_sharp_edges(sm, featureAngleDeg, sharp);
    for (auto e : sm.edges())
        count += sharp[e] ? 1 : 0;
    sm.remove_property_map(sharp);
    return count;
}

/// Runs the enabled optimizers on the refined complex.
void optimize(C3t3& c3t3, const Domain& domain, const MeshingParams& p, const Progress& progress) {
    namespace cp = CGAL::parameters;
    // ---- optimizers (same order as make_mesh_3) ---------------------------------------------
    if (p.odt) {
        progress.begin(MeshingStage::Odt);
        CGAL::odt_optimize_mesh_3(c3t3, domain, cp::max_iteration_number = p.smoothingMaxIterations);
    }
    if (p.lloyd) {
        progress.begin(MeshingStage::Lloyd);
        CGAL::lloyd_optimize_mesh_3(c3t3, domain, cp::max_iteration_number = p.smoothingMaxIterations);
    }
    if (p.perturb) {
        progress.begin(MeshingStage::Perturb);
        CGAL::perturb_mesh_3(c3t3, domain);
    }
    if (p.exude) {
        progress.begin(MeshingStage::Exude);
        CGAL::exude_mesh_3(c3t3);
    }
}

/// A grid of points hashed by cell (side `cell`): which stored point lies within `reach` of a query
/// (reach <= cell).
class PointGrid {
public:
    explicit PointGrid(double cell) : m_cell(cell) {}
    void add(const sim::Vec3& p) { m_cells[key(cellOf(p))].push_back(p); }
    bool near(const sim::Vec3& p, double reach) const {
        const std::array<int64_t, 3> c = cellOf(p);
        for (int64_t dz = -1; dz <= 1; ++dz)
            for (int64_t dy = -1; dy <= 1; ++dy)
                for (int64_t dx = -1; dx <= 1; ++dx) {
                    const auto it = m_cells.find(key({c[0] + dx, c[1] + dy, c[2] + dz}));
                    if (it == m_cells.end()) continue;
                    for (const sim::Vec3& q : it->second)
                        if ((q - p).squaredNorm() <= reach * reach) return true;
                }
        return false;
    }

private:
    std::array<int64_t, 3> cellOf(const sim::Vec3& p) const {
        return {static_cast<int64_t>(std::floor(p.x() / m_cell)), static_cast<int64_t>(std::floor(p.y() / m_cell)),
                static_cast<int64_t>(std::floor(p.z() / m_cell))};
    }
    static uint64_t key(const std::array<int64_t, 3>& c) {
        return (static_cast<uint64_t>(c[0] & 0x1FFFFF) << 42) | (static_cast<uint64_t>(c[1] & 0x1FFFFF) << 21) |
               static_cast<uint64_t>(c[2] & 0x1FFFFF);
    }
    double m_cell;
    std::unordered_map<uint64_t, std::vector<sim::Vec3>> m_cells;
};

/// Delaunay refinement starts from a few points shot at the surface and grows the mesh where its
/// restricted facets are bad; a thin part the first points and their Voronoi edges never meet
/// (a 3 mm artery beside a gallbladder, meshed at 3 mm) stays out of the mesh altogether. Seeds
/// such parts: every input triangle whose centre lies farther than 1.5 facet sizes from each
/// vertex of the complex's boundary gives a surface point (one per facet-size cell, with the
/// domain's own patch index), inserted into the triangulation. Returns the number inserted; the
/// caller refines again (refine_mesh_3 rescans a triangulation that gained vertices).
size_t seedMissedSurface(C3t3& c3t3, const Domain& domain, const sim::TriMesh& surface, const MeshingParams& p) {
    const double reach = 1.5 * p.facetSize;
    Tr& tr = c3t3.triangulation();
    const auto point = tr.geom_traits().construct_point_3_object();
    PointGrid boundary(reach), seeded(p.facetSize);
    for (auto f = c3t3.facets_in_complex_begin(); f != c3t3.facets_in_complex_end(); ++f)
        for (int k = 1; k < 4; ++k) {
            const K::Point_3 q = point(tr.point(f->first->vertex((f->second + k) % 4)));
            boundary.add(sim::Vec3(q.x(), q.y(), q.z()));
        }
    const auto intersect = domain.construct_intersection_object();
    const auto weighted = tr.geom_traits().construct_weighted_point_3_object();
    size_t inserted = 0;
    for (const sim::Tri& t : surface.triangles()) {
        const sim::Vec3& a = surface.positions()[t[0]];
        const sim::Vec3& b = surface.positions()[t[1]];
        const sim::Vec3& c = surface.positions()[t[2]];
        const sim::Vec3 centre = (a + b + c) / 3;
        if (boundary.near(centre, reach) || seeded.near(centre, p.facetSize)) continue;
        const sim::Vec3 n = (b - a).cross(c - a).normalized() * std::max(p.facetDistance, 1e-6);
        const sim::Vec3 from = centre - n, to = centre + n;
        const Domain::Intersection hit =
            intersect(K::Segment_3(K::Point_3(from.x(), from.y(), from.z()), K::Point_3(to.x(), to.y(), to.z())));
        if (std::get<2>(hit) != 2) continue; // no surface point with a patch index
        const Tr::Vertex_handle v = tr.insert(weighted(std::get<0>(hit)));
        if (v == Tr::Vertex_handle()) continue; // hidden by a protecting ball
        c3t3.set_dimension(v, 2);
        c3t3.set_index(v, std::get<1>(hit));
        seeded.add(centre);
        ++inserted;
    }
    return inserted;
}

/// The cells of a complex as arrays: compact vertices, positively oriented tets.
struct TetArrays {
    std::vector<sim::Vec3> positions;
    std::vector<sim::Tet> tets;
    double volume = 0;
};

TetArrays exportTets(const C3t3& c3t3) {
    const Tr& tr = c3t3.triangulation();
    const auto point = tr.geom_traits().construct_point_3_object();
    std::unordered_map<Tr::Vertex_handle, int32_t> vertexIndex;
    TetArrays out;
    std::vector<sim::Vec3>& positions = out.positions;
    out.tets.reserve(c3t3.number_of_cells_in_complex());
    for (auto c = c3t3.cells_in_complex_begin(); c != c3t3.cells_in_complex_end(); ++c) {
        sim::Tet tet{};
        for (int i = 0; i < 4; ++i) {
            const Tr::Vertex_handle vh = c->vertex(i);
            const auto [it, inserted] = vertexIndex.try_emplace(vh, static_cast<int32_t>(positions.size()));
            if (inserted) {
                const K::Point_3 q = point(tr.point(vh));
                positions.emplace_back(q.x(), q.y(), q.z());
            }
            tet[i] = it->second;
        }
        const sim::Vec3& a = positions[tet[0]];
        const double vol = (positions[tet[1]] - a).cross(positions[tet[2]] - a).dot(positions[tet[3]] - a);
        if (vol < 0) std::swap(tet[2], tet[3]);
        out.volume += std::abs(vol) / 6;
        out.tets.push_back(tet);
    }
    return out;
}

} // namespace

std::string_view stageName(MeshingStage stage) {

    switch (stage) {
    case MeshingStage::CheckSurface:
        return "check surface";
    case MeshingStage::BuildDomain:
        return "build domain";
    case MeshingStage::Refine:
        return "refine";
    case MeshingStage::Odt:
        return "odt";
    case MeshingStage::Lloyd:
        return "lloyd";
    case MeshingStage::Perturb:
        return "perturb";
    case MeshingStage::Exude:
        return "exude";
    case MeshingStage::Export:
        return "export";
    }
    return "unknown";
}

TetrahedralizeResult tetrahedralize(const sim::TriMesh& surface, const MeshingParams& params,
                                    ProgressCallback progressCallback) {
    const auto t0 = std::chrono::steady_clock::now();
    validateParams(params);
    const std::string& label = params.label;
    const Progress progress(std::move(progressCallback), params);
    MeshingReport report;

    // ---- surface checks ----------------------------------------------------------------------
    progress.begin(MeshingStage::CheckSurface);
    detail::checkInputSurface(label, surface);
    try {
        SurfaceMesh sm = buildSurfaceMesh(label, surface);
        report.surfaceVolume = std::abs(surface.signedVolume());

        // ---- parameters with automatic values -------------------------------------------------
        const MeshingParams p = resolveParams(label, surface, params, report);

        // ---- domain and refinement --------------------------------------------------------------
        progress.begin(MeshingStage::BuildDomain);
        const DefaultRandomScope randomScope(p.seed);
        CGAL::Random domainRandom(p.seed);
        if (p.featureAngleDeg > 0) report.featureEdgeCount += countSharpEdges(sm, p.featureAngleDeg);
        Domain domain(sm, &domainRandom);
        if (p.featureAngleDeg > 0) domain.detect_features(p.featureAngleDeg);

        namespace cp = CGAL::parameters;
        const Criteria criteria(cp::edge_size = p.edgeSize, cp::facet_angle = p.facetAngleDeg,
                                cp::facet_size = p.facetSize, cp::facet_distance = p.facetDistance,
                                cp::cell_radius_edge_ratio = p.cellRadiusEdgeRatio, cp::cell_size = p.cellSize);
        progress.begin(MeshingStage::Refine);
        C3t3 c3t3 =
            CGAL::make_mesh_3<C3t3>(domain, criteria, cp::no_perturb(), cp::no_exude(), cp::no_odt(), cp::no_lloyd());
        if (p.seedMissedSurface) report.missedSurfaceSeeds = seedMissedSurface(c3t3, domain, surface, p);
        if (report.missedSurfaceSeeds > 0)
            CGAL::refine_mesh_3(c3t3, domain, criteria, cp::no_perturb(), cp::no_exude(), cp::no_odt(), cp::no_lloyd());
        const auto tOpt = std::chrono::steady_clock::now();
        report.refineSeconds = std::chrono::duration<double>(tOpt - t0).count();
        optimize(c3t3, domain, p, progress);
        report.optimizeSeconds = secondsSince(tOpt);

        // ---- export: cells of the complex, compact vertices, positive orientation --------------
        progress.begin(MeshingStage::Export);
        if (c3t3.number_of_cells_in_complex() == 0)
            fail(label, "meshing produced no tets (sizes too large for the surface?)");
        TetArrays arrays = exportTets(c3t3);
        report.boundaryTriangleCount = c3t3.number_of_facets_in_complex();

        TetrahedralizeResult result;
        result.mesh = sim::TetMesh::fromArrays(std::move(arrays.positions), std::move(arrays.tets),
                                               "bake::tetrahedralize(" + label + ")");
        report.vertexCount = result.mesh->vertexCount();
        report.tetCount = result.mesh->tetCount();
        report.quality = result.mesh->quality();
        report.tetVolume = arrays.volume;
        report.volumeRelError = (report.tetVolume - report.surfaceVolume) / report.surfaceVolume;
        report.totalSeconds = secondsSince(t0);
        result.report = std::move(report);
        progress.done();
        return result;
    } catch (const CGAL::Failure_exception& e) {
        fail(label, std::string("meshing failed in CGAL: ") + e.what());
    }
}

} // namespace viscera::bake
