// Mean curvature flow skeleton [A §4.3.5] with CGAL::Mean_curvature_flow_skeletonization. Like
// tetrahedralize.cpp, the only place that sees these CGAL headers.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif

// The skeletonization's default sparse solver is Eigen's SimplicialLDLT, enabled by this macro
// (Eigen is already a public dependency of viscera::sim). Defined here only, so the rest of
// viscera::bake compiles as before.
#ifndef CGAL_EIGEN3_ENABLED
#define CGAL_EIGEN3_ENABLED 1
#endif

#include "bake/skeleton.hpp"
#include "bake/surface_check.hpp"

#include "sim/util/error.hpp"

#include <sys/mman.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <new>

// Determinism. CGAL's skeletonization keeps its edge-collapse queue in a std::set of Polyhedron
// edge handles, ordered by their memory addresses, so with the default allocator the collapse
// order (and the skeleton) depends on the heap's history: two calls in one process gave different
// skeletons. The skeletonization's internal Polyhedron therefore allocates from a monotonic arena,
// one contiguous reserved address range per call: addresses grow with allocation order, so the
// order of handles is their creation order and the result is bit-identical from call to call.
// CGAL_ALLOCATOR is CGAL's hook for the default allocator. It is switched to the arena only while
// the Polyhedron / halfedge-data-structure headers are read (their default template arguments
// then name the arena, giving types distinct from those of any other translation unit) and
// restored before the skeletonization header; every other CGAL header is included before, with
// the standard allocator, so no type shared with other translation units changes (ODR).
// A static_assert below checks that the skeletonization's Polyhedron did get the arena.
namespace viscera::bake::detail {

class ScratchArena {
public:
    explicit ScratchArena(size_t reserveBytes) : m_size(reserveBytes) {
        void* p = ::mmap(nullptr, m_size, PROT_NONE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
        if (p == MAP_FAILED) throw std::bad_alloc();
        m_base = static_cast<std::byte*>(p);
        m_previous = s_current;
        s_current = this;
    }
    ~ScratchArena() {
        s_current = m_previous;
        ::munmap(m_base, m_size);
    }
    ScratchArena(const ScratchArena&) = delete;
    ScratchArena& operator=(const ScratchArena&) = delete;

    static ScratchArena* current() { return s_current; }
    size_t used() const { return m_used; }

    void* allocate(size_t bytes, size_t align) {
        const size_t start = (m_used + align - 1) / align * align;
        if (bytes > m_size - start) throw std::bad_alloc();
        const size_t end = start + bytes;
        if (end > m_committed) { // make pages readable/writable in 16 MiB steps
            const size_t step = size_t{16} << 20;
            const size_t commit = std::min(m_size, (end + step - 1) / step * step);
            if (::mprotect(m_base + m_committed, commit - m_committed, PROT_READ | PROT_WRITE) != 0)
                throw std::bad_alloc();
            m_committed = commit;
        }
        m_used = end;
        return m_base + start;
    }
    bool owns(const void* p) const {
        const auto* b = static_cast<const std::byte*>(p);
        return b >= m_base && b < m_base + m_size;
    }

private:
    static thread_local ScratchArena* s_current;
    std::byte* m_base = nullptr;
    size_t m_size = 0, m_used = 0, m_committed = 0;
    ScratchArena* m_previous = nullptr;
};
thread_local ScratchArena* ScratchArena::s_current = nullptr;

/// Allocates from the current thread's arena (deallocation is a no-op there; the arena is released
/// as a whole), or from the heap when no arena is active.
template <class T> struct ArenaAllocator {
    using value_type = T;
    template <class U> struct rebind { using other = ArenaAllocator<U>; };
    ArenaAllocator() noexcept = default;
    template <class U> ArenaAllocator(const ArenaAllocator<U>&) noexcept {}
    T* allocate(size_t n) {
        if (ScratchArena* a = ScratchArena::current()) return static_cast<T*>(a->allocate(n * sizeof(T), alignof(T)));
        return std::allocator<T>().allocate(n);
    }
    void deallocate(T* p, size_t n) noexcept {
        const ScratchArena* a = ScratchArena::current();
        if (a && a->owns(p)) return;
        std::allocator<T>().deallocate(p, n);
    }
    template <class U> friend bool operator==(const ArenaAllocator&, const ArenaAllocator<U>&) noexcept { return true; }
};

} // namespace viscera::bake::detail

// Everything the skeletonization needs except the Polyhedron, with the standard allocator.
#include <CGAL/Bbox_3.h>
#include <CGAL/Default.h>
#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Delaunay_triangulation_cell_base_3.h>
#include <CGAL/Eigen_solver_traits.h>
#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/compute_normal.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Side_of_triangle_mesh.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Timer.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>
#include <CGAL/Weights/cotangent_weights.h>
#include <CGAL/boost/graph/Euler_operations.h>
#include <CGAL/boost/graph/copy_face_graph.h>
#include <CGAL/exceptions.h>
#include <CGAL/memory.h>

// The Polyhedron and its halfedge data structure, with the arena as default allocator.
#undef CGAL_ALLOCATOR
#define CGAL_ALLOCATOR(T) ::viscera::bake::detail::ArenaAllocator<T>
#include <CGAL/HalfedgeDS_default.h>
#include <CGAL/HalfedgeDS_list.h>
#include <CGAL/In_place_list.h>
#include <CGAL/Polyhedron_3.h>
#include <CGAL/Polyhedron_items_with_id_3.h>
#include <CGAL/boost/graph/graph_traits_Polyhedron_3.h>
#undef CGAL_ALLOCATOR
#define CGAL_ALLOCATOR(T) std::allocator<T>

#include <CGAL/Mean_curvature_flow_skeletonization.h>

#include <boost/graph/adjacency_list.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iterator>
#include <limits>
#include <numbers>
#include <set>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <unordered_map>
#include <utility>
#include <vector>

namespace viscera::bake {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using SurfaceMesh = CGAL::Surface_mesh<K::Point_3>;
using Skeletonization = CGAL::Mean_curvature_flow_skeletonization<SurfaceMesh>;
using CgalSkeleton = Skeletonization::Skeleton;
static_assert(std::is_same_v<Skeletonization::mTriangleMesh,
                             CGAL::Polyhedron_3<K, CGAL::internal::Skel_polyhedron_items_3<SurfaceMesh::Vertex_index>,
                                                CGAL::HalfedgeDS_default, detail::ArenaAllocator<int>>>,
              "the skeletonization's Polyhedron must allocate from the arena (include order above)");
namespace PMP = CGAL::Polygon_mesh_processing;

[[noreturn]] void fail(const std::string& label, const std::string& message) {
    throw InputError(label + ": " + message);
}

void requireParam(bool ok, const char* field, double value, const char* rule) {
    if (!ok)
        throw std::invalid_argument(std::string("bake::extractSkeleton(): SkeletonParams::") + field + " is " +
                                    std::to_string(value) + " (" + rule + ")");
}

void validateParams(const SkeletonParams& p) {
    requireParam(std::isfinite(p.maxTriangleAngleDeg) && p.maxTriangleAngleDeg > 90 && p.maxTriangleAngleDeg < 180,
                 "maxTriangleAngleDeg", p.maxTriangleAngleDeg, "must be in (90, 180)");
    requireParam(std::isfinite(p.minEdgeLengthRel) && p.minEdgeLengthRel > 0 && p.minEdgeLengthRel <= 0.1,
                 "minEdgeLengthRel", p.minEdgeLengthRel, "must be in (0, 0.1]");
    requireParam(std::isfinite(p.areaVariationFactor) && p.areaVariationFactor > 0 && p.areaVariationFactor < 1,
                 "areaVariationFactor", p.areaVariationFactor, "must be in (0, 1)");
    requireParam(p.maxIterations >= 1, "maxIterations", static_cast<double>(p.maxIterations), "must be >= 1");
    requireParam(std::isfinite(p.qualitySpeedTradeoff) && p.qualitySpeedTradeoff > 0, "qualitySpeedTradeoff",
                 p.qualitySpeedTradeoff, "must be finite and > 0");
    requireParam(std::isfinite(p.mediallyCenteredSpeedTradeoff) && p.mediallyCenteredSpeedTradeoff > 0,
                 "mediallyCenteredSpeedTradeoff", p.mediallyCenteredSpeedTradeoff, "must be finite and > 0");
}

double secondsSince(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// The normalized frame of the surface: bounding-box centre at the origin, unit diagonal; and
/// which vertices the triangles reference.
struct NormalizedFrame {
    std::vector<char> used;
    sim::Vec3 centre;
    double diagonal = 0;
    double scale = 0;
};

NormalizedFrame normalizedFrame(const std::string& label, const sim::TriMesh& surface) {
    // Normalized frame: bounding-box centre at the origin, unit diagonal.
    NormalizedFrame frame;
    frame.used.assign(surface.vertexCount(), 0);
    sim::Vec3 lo = sim::Vec3::Constant(HUGE_VAL), hi = sim::Vec3::Constant(-HUGE_VAL);
    for (const sim::Tri& t : surface.triangles())
        for (int32_t v : t) {
            frame.used[v] = 1;
            lo = lo.cwiseMin(surface.positions()[v]);
            hi = hi.cwiseMax(surface.positions()[v]);
        }
    frame.diagonal = (hi - lo).norm();
    if (!(frame.diagonal > 0)) fail(label, "surface has zero extent");
    frame.centre = 0.5 * (lo + hi);
    frame.scale = 1.0 / frame.diagonal;
    return frame;
}

/// The CGAL surface in the normalized frame, with the map back to the input's vertices.
struct CgalSurface {
    SurfaceMesh sm;
    std::vector<int32_t> inputOf; // Surface_mesh vertex index -> surface vertex
};

/// Fills `out` from the referenced vertices; checks degenerate and non-manifold triangles.
void buildSurfaceMesh(const std::string& label, const sim::TriMesh& surface, const NormalizedFrame& frame,
                      CgalSurface& out) {
    SurfaceMesh& sm = out.sm;
    std::vector<SurfaceMesh::Vertex_index> vmap(surface.vertexCount());
    out.inputOf.reserve(surface.vertexCount());
    for (size_t v = 0; v < surface.vertexCount(); ++v)
        if (frame.used[v]) {
            const sim::Vec3 p = (surface.positions()[v] - frame.centre) * frame.scale;
            vmap[v] = sm.add_vertex(K::Point_3(p.x(), p.y(), p.z()));
            out.inputOf.push_back(static_cast<int32_t>(v));
        }
    const auto& tris = surface.triangles();
    for (size_t t = 0; t < tris.size(); ++t) {
        if (CGAL::collinear(sm.point(vmap[tris[t][0]]), sm.point(vmap[tris[t][1]]), sm.point(vmap[tris[t][2]])))
            fail(label, "triangle " + std::to_string(t) + " is degenerate (zero area)");
        if (sm.add_face(vmap[tris[t][0]], vmap[tris[t][1]], vmap[tris[t][2]]) == SurfaceMesh::null_face())
            fail(label, "surface is not manifold at triangle " + std::to_string(t));
    }
}

void checkSelfIntersections(const std::string& label, const SurfaceMesh& sm) {
    std::vector<std::pair<SurfaceMesh::Face_index, SurfaceMesh::Face_index>> pairs;
    PMP::self_intersections(sm, std::back_inserter(pairs));
    if (!pairs.empty()) {
        std::pair<size_t, size_t> first(std::numeric_limits<size_t>::max(), 0);
        for (const auto& [f, g] : pairs) {
            const size_t a = f, b = g;
            first = std::min(first, std::pair<size_t, size_t>(std::min(a, b), std::max(a, b)));
        }
        fail(label, "surface self-intersects: triangles " + std::to_string(first.first) + " and " +
                        std::to_string(first.second) + " intersect (" + std::to_string(pairs.size()) +
                        " intersecting pair(s) in all)");
    }
}

/// Runs the mean curvature flow contraction of `sm` into `cs`; `reserveBytes` is the arena's size
/// and `surfaceTriangles` the input's triangle count (both for the out-of-memory message).
void contract(const SurfaceMesh& sm, const SkeletonParams& params, size_t reserveBytes, size_t surfaceTriangles,
              CgalSkeleton& cs) {
    const std::string& label = params.label;
    try {
        Skeletonization mcfs(sm);
        mcfs.set_max_triangle_angle(params.maxTriangleAngleDeg * std::numbers::pi / 180.0);
        mcfs.set_min_edge_length(params.minEdgeLengthRel); // diagonal is 1 in this frame
        mcfs.set_area_variation_factor(params.areaVariationFactor);
        mcfs.set_max_iterations(params.maxIterations);
        mcfs.set_quality_speed_tradeoff(params.qualitySpeedTradeoff);
        mcfs.set_is_medially_centered(params.mediallyCentered);
        mcfs.set_medially_centered_speed_tradeoff(params.mediallyCenteredSpeedTradeoff);
        mcfs(cs);
    } catch (const CGAL::Failure_exception& e) {
        fail(label, std::string("skeletonization failed: ") + e.what());
    } catch (const std::bad_alloc&) {
        fail(label, "skeletonization needs more than " + std::to_string(reserveBytes >> 20) +
                        " MiB of scratch memory (surface of " + std::to_string(surfaceTriangles) +
                        " triangles; simplify it first)");
    }
}

/// Nodes (back in the input frame) with the vertices they list, and the edges, of `cs` into `s`.
void exportSkeleton(const std::string& label, const sim::TriMesh& surface, const NormalizedFrame& frame,
                    const std::vector<int32_t>& inputOf, const CgalSkeleton& cs, sim::Skeleton& s) {
    const size_t m = boost::num_vertices(cs);
    if (m == 0) fail(label, "skeletonization produced no skeleton nodes");
    s.nodes.resize(m);
    s.vertexNode.assign(surface.vertexCount(), sim::kNone);
    for (size_t j = 0; j < m; ++j) {
        const auto& vm = cs[j];
        s.nodes[j] = sim::Vec3(vm.point.x(), vm.point.y(), vm.point.z()) / frame.scale + frame.centre;
        if (!s.nodes[j].allFinite())
            fail(label, "skeletonization produced a non-finite node (" + std::to_string(j) + ")");
        for (const SurfaceMesh::Vertex_index vd : vm.vertices) {
            const int32_t v = inputOf.at(static_cast<size_t>(vd));
            if (s.vertexNode[v] == sim::kNone) s.vertexNode[v] = static_cast<int32_t>(j);
        }
    }
    std::set<std::pair<int32_t, int32_t>> edges;
    for (auto [it, end] = boost::edges(cs); it != end; ++it) {
        const auto a = static_cast<int32_t>(boost::source(*it, cs));
        const auto b = static_cast<int32_t>(boost::target(*it, cs));
        if (a != b) edges.emplace(std::min(a, b), std::max(a, b));
    }
    s.edges.reserve(edges.size());
    for (const auto& [a, b] : edges)
        s.edges.push_back({a, b});
}

/// Assigns the nearest node to each referenced vertex that no node lists; returns their count.
size_t assignUnlistedVertices(const sim::TriMesh& surface, const std::vector<char>& used, sim::Skeleton& s) {
    // Vertices the correspondence did not list (not expected): nearest node.
    size_t unlisted = 0;
    for (size_t v = 0; v < surface.vertexCount(); ++v) {
        if (!used[v] || s.vertexNode[v] != sim::kNone) continue;
        double best = HUGE_VAL;
        for (size_t j = 0; j < s.nodes.size(); ++j) {
            const double d = (surface.positions()[v] - s.nodes[j]).squaredNorm();
            if (d < best) {
                best = d;
                s.vertexNode[v] = static_cast<int32_t>(j);
            }
        }
        ++unlisted;
    }
    return unlisted;
}

} // namespace

SkeletonResult extractSkeleton(const sim::TriMesh& surface, const SkeletonParams& params) {
    const auto t0 = std::chrono::steady_clock::now();
    validateParams(params);
    const std::string& label = params.label;
    // Declared first, so every CGAL object of this call is destroyed before it (see above).
    const size_t reserveBytes =
        std::min(size_t{1} << 40, (size_t{1} << 30) + (size_t{256} << 10) * surface.triangleCount());
    const detail::ScratchArena arena(reserveBytes);

    // ---- surface checks (indices of `surface` in every message) ------------------------------
    detail::checkInputSurface(label, surface);
    const NormalizedFrame frame = normalizedFrame(label, surface);
    CgalSurface input;
    buildSurfaceMesh(label, surface, frame, input);
    checkSelfIntersections(label, input.sm);
    const double diagonal = frame.diagonal;
    const double volume = std::abs(surface.signedVolume());
    if (!(volume > 1e-12 * diagonal * diagonal * diagonal))
        fail(label, "surface encloses no volume (" + std::to_string(volume) + " m^3)");

    // ---- contraction ---------------------------------------------------------------------------
    CgalSkeleton cs;
    contract(input.sm, params, reserveBytes, surface.triangleCount(), cs);

    // ---- export ----------------------------------------------------------------------------------
    SkeletonResult result;
    sim::Skeleton& s = result.skeleton;
    exportSkeleton(label, surface, frame, input.inputOf, cs, s);
    SkeletonReport& r = result.report;
    r.unlistedVertices += assignUnlistedVertices(surface, frame.used, s);

    r.surfaceVertices = input.inputOf.size();
    r.surfaceTriangles = surface.triangleCount();
    r.nodes = s.nodes.size();
    r.edges = s.edges.size();
    std::vector<int32_t> comp;
    r.components = s.components(comp);
    r.cycleRank = s.cycleRank();
    r.scratchBytes = arena.used();
    r.seconds = secondsSince(t0);
    return result;
}

SkeletonResult extractSkeleton(sim::TetMesh& mesh, const SkeletonParams& params) {
    mesh.requireLevel(3);
    const sim::TriMesh& boundary = mesh.boundary();
    const std::vector<int32_t>& toMesh = mesh.boundaryVertexMap();
    SkeletonResult r = extractSkeleton(boundary, params);
    std::vector<int32_t> vertexNode(mesh.vertexCount(), sim::kNone);
    for (size_t b = 0; b < toMesh.size() && b < r.skeleton.vertexNode.size(); ++b)
        vertexNode[toMesh[b]] = r.skeleton.vertexNode[b];
    r.skeleton.vertexNode = std::move(vertexNode);
    return r;
}

} // namespace viscera::bake
