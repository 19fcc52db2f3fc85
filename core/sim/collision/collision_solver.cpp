#include "sim/collision/collision_solver.hpp"

#include "sim/collision/distance.hpp"
#include "sim/xpbd/xpbd_solver.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace viscera::sim {

const char* toString(CollisionMethod m) {
    switch (m) {
    case CollisionMethod::Circumsphere:
        return "circumsphere";
    case CollisionMethod::BoundingSphere:
        return "bounding_sphere";
    case CollisionMethod::Polygon:
        return "polygon";
    case CollisionMethod::PolygonFeatures:
        return "polygon_features";
    }
    return "unknown";
}

bool parseCollisionMethod(const std::string& name, CollisionMethod& out) {
    for (CollisionMethod m : {CollisionMethod::Circumsphere, CollisionMethod::BoundingSphere, CollisionMethod::Polygon,
                              CollisionMethod::PolygonFeatures})
        if (name == toString(m)) {
            out = m;
            return true;
        }
    return false;
}

std::string validate(const CollisionSettings& s) {
    if (std::string e = validate(s.circumsphere); !e.empty()) return e;
    if (!(s.polygonMargin >= 0) || !std::isfinite(s.polygonMargin)) return "polygon margin must be finite and >= 0";
    if (!(s.compliance >= 0) || !std::isfinite(s.compliance)) return "compliance must be finite and >= 0";
    if (!(s.maxCorrectionPerStep > 0)) return "max correction per step must be > 0";
    if (!(s.reachListMargin >= 0) || !std::isfinite(s.reachListMargin))
        return "reach list margin must be finite and >= 0";
    if (!(s.reachListToolMargin >= 0) || !std::isfinite(s.reachListToolMargin))
        return "reach list tool margin must be finite and >= 0";
    return {};
}

CollisionSurfaceDesc CollisionSurfaceDesc::fromTetMesh(const TetMesh& mesh, std::vector<double> inverseMass) {
    CollisionSurfaceDesc d;
    const TriMesh& b = mesh.boundary();
    const std::vector<int32_t>& map = mesh.boundaryVertexMap();
    d.triangles.reserve(b.triangleCount());
    for (const Tri& t : b.triangles())
        d.triangles.push_back({map[t[0]], map[t[1]], map[t[2]]});
    d.restPositions = mesh.positions();
    d.inverseMass = std::move(inverseMass);
    return d;
}

double unifiedTriangleConstraint(const std::array<Vec3, 3>& x, const std::array<Vec3, 3>& target, bool squared,
                                 std::array<Vec3, 3>* grad) {
    double sum = 0;
    for (int k = 0; k < 3; ++k)
        sum += (x[k] - target[k]).squaredNorm();
    const double C = squared ? sum : std::sqrt(sum);
    if (grad)
        for (int k = 0; k < 3; ++k)
            (*grad)[k] = squared ? Vec3(2 * (x[k] - target[k])) : (C > 0 ? Vec3((x[k] - target[k]) / C) : Vec3::Zero());
    return C;
}

double pointTriangleConstraint(const std::array<Vec3, 3>& x, const Vec3& bary, const Vec3& q, double reach,
                               std::array<Vec3, 3>* grad) {
    const Vec3 d = bary[0] * x[0] + bary[1] * x[1] + bary[2] * x[2] - q;
    const double dist = d.norm();
    if (grad) {
        const Vec3 n = dist > 0 ? Vec3(d / dist) : Vec3::Zero();
        for (int k = 0; k < 3; ++k)
            (*grad)[k] = bary[k] * n;
    }
    return dist - reach;
}

CollisionSolver::~CollisionSolver() = default;

std::unique_ptr<CollisionSolver> CollisionSolver::create(CollisionSurfaceDesc desc, const CollisionSettings& settings) {
    const std::string where = "sim::CollisionSolver::create(): ";
    if (std::string e = validate(settings); !e.empty()) throw std::invalid_argument(where + e);
    const size_t nv = desc.restPositions.size();
    if (desc.triangles.empty()) throw std::invalid_argument(where + "the surface has no triangles");
    if (desc.inverseMass.size() != nv)
        throw std::invalid_argument(where + "inverse masses: " + std::to_string(desc.inverseMass.size()) +
                                    " values for " + std::to_string(nv) + " vertices");
    for (size_t v = 0; v < nv; ++v) {
        if (!desc.restPositions[v].allFinite())
            throw std::invalid_argument(where + "vertex " + std::to_string(v) + " has a non-finite rest position");
        if (!(desc.inverseMass[v] >= 0) || !std::isfinite(desc.inverseMass[v]))
            throw std::invalid_argument(where + "vertex " + std::to_string(v) +
                                        " has an inverse mass that is negative or not finite");
    }
    for (size_t t = 0; t < desc.triangles.size(); ++t)
        for (int32_t v : desc.triangles[t])
            if (v < 0 || static_cast<size_t>(v) >= nv)
                throw std::invalid_argument(where + "triangle " + std::to_string(t) + " references vertex " +
                                            std::to_string(v) + " (surface has " + std::to_string(nv) + " vertices)");
    std::unique_ptr<CollisionSolver> s(new CollisionSolver());
    s->m_settings = settings;
    s->m_tris = std::move(desc.triangles);
    s->m_rest = std::move(desc.restPositions);
    s->m_w = std::move(desc.inverseMass);
    s->m_curv = SurfaceCurvature(nv, s->m_tris);
    s->m_h3Spline = curvatureHermite(settings.circumsphere.curvatureThreshold);
    s->m_offsetPerRadius = offsetPerRadius(settings.circumsphere);
    const size_t nt = s->m_tris.size();
    s->m_h3.assign(nt, 1.0);
    s->m_energy.assign(nt, 0.0);
    s->m_refArea.assign(nt, -1.0);
    s->m_touched.assign(nv, 0);
    s->m_vertexTriStart.assign(nv + 1, 0);
    for (const Tri& f : s->m_tris)
        for (int32_t v : f)
            ++s->m_vertexTriStart[v + 1];
    for (size_t v = 0; v < nv; ++v)
        s->m_vertexTriStart[v + 1] += s->m_vertexTriStart[v];
    s->m_vertexTris.resize(s->m_vertexTriStart.back());
    std::vector<uint32_t> fill(s->m_vertexTriStart.begin(), s->m_vertexTriStart.end() - 1);
    for (size_t t = 0; t < nt; ++t)
        for (int32_t v : s->m_tris[t])
            s->m_vertexTris[fill[v]++] = static_cast<int32_t>(t);
    s->refreshAllFactors(s->m_rest);
    return s;
}

void CollisionSolver::refreshFactors(int32_t t, const std::vector<Vec3>& x, double area) {
    const Tri& f = m_tris[t];
    m_h3[t] = m_h3Spline.value(m_curv.triangleCurvature(t, x));
    m_energy[t] = triangleEnergyFactor({m_rest[f[0]], m_rest[f[1]], m_rest[f[2]]}, {x[f[0]], x[f[1]], x[f[2]]});
    m_refArea[t] = area;
}

void CollisionSolver::refreshAllFactors(const std::vector<Vec3>& x) {
    if (x.size() != m_rest.size()) return;
    m_reachValid = false; // the list was made with the old factors
    for (size_t t = 0; t < m_tris.size(); ++t) {
        const Tri& f = m_tris[t];
        const double area = 0.5 * (x[f[1]] - x[f[0]]).cross(x[f[2]] - x[f[0]]).norm();
        refreshFactors(static_cast<int32_t>(t), x, area);
    }
}

Sphere CollisionSolver::triangleSphere(int32_t t, const std::vector<Vec3>& x) const {
    const Tri& f = m_tris[t];
    if (m_settings.method != CollisionMethod::Circumsphere) return boundingSphere(x[f[0]], x[f[1]], x[f[2]]);
    const Circumcircle cc = circumcircle(x[f[0]], x[f[1]], x[f[2]]);
    return circumsphere(cc, circumsphereOffset(cc.radius, m_h3[t], m_energy[t], m_offsetPerRadius,
                                               m_settings.circumsphere.energyScale));
}

// Broad phase: one query (the tool's box) per step, so each listed triangle's box is tested
// directly, in triangle order (a spatial hash rebuilt every substep for a single query cost more
// than the test). Circumsphere: a triangle whose vertex box, grown by circumsphereReach (a bound
// on how far its sphere, or the sphere's safe-cone part, can reach beyond it), misses the tool is
// no candidate, and its sphere is not computed.
bool CollisionSolver::broadPhaseHit(int32_t t, const std::vector<Vec3>& x, const Aabb& toolBox) const {
    const bool polygon =
        m_settings.method == CollisionMethod::Polygon || m_settings.method == CollisionMethod::PolygonFeatures;
    const Tri& f = m_tris[t];
    Aabb b;
    const Vec3 lo = x[f[0]].cwiseMin(x[f[1]]).cwiseMin(x[f[2]]);
    const Vec3 hi = x[f[0]].cwiseMax(x[f[1]]).cwiseMax(x[f[2]]);
    if (polygon) {
        const Vec3 m = Vec3::Constant(m_settings.polygonMargin);
        b.lo = lo - m;
        b.hi = hi + m;
    } else {
        if (m_settings.method == CollisionMethod::Circumsphere) {
            const Vec3 reach = Vec3::Constant(circumsphereReach(t, x, 0));
            if (!Aabb{lo - reach, hi + reach}.overlaps(toolBox)) return false; // also skips non-finite vertices
        }
        const Sphere s = triangleSphere(t, x);
        if (m_settings.safeConeOnly && s.coneCos > -1) {
            // Only the safe cone inside the sphere can hold a contact: the cap lies within the
            // circumcircle's radius of the circumcentre, and the cone narrows from there to the
            // sphere centre. Box of that ball and the centre (exact for the contacts at x; about
            // a sixth of the sphere's box for a flat surface).
            const double c = std::clamp(s.coneCos, 0.0, 1.0);
            const Vec3 rim = s.centre + s.radius * c * s.coneAxis; // circumcentre
            const Vec3 R = Vec3::Constant(s.radius * std::sqrt(1 - c * c));
            b.lo = (rim - R).cwiseMin(s.centre);
            b.hi = (rim + R).cwiseMax(s.centre);
        } else {
            b.lo = s.centre - Vec3::Constant(s.radius);
            b.hi = s.centre + Vec3::Constant(s.radius);
        }
    }
    return b.lo.allFinite() && b.hi.allFinite() && b.overlaps(toolBox);
}

// Within the margin μ (each vertex moved at most μ along each axis, so at most √3 μ) the vertex
// box grows by at most μ per side, every edge vector changes by at most δ = 2√3 μ, and twice the
// area |e₁ × e₂| by at most δ(|e₁| + |e₂|) + δ². The radius the sphere methods use is at most
// min(R, 4ℓ) (circumsphere.cpp, circumcircle(): a circumradius R over 4 × the longest edge ℓ falls back to the
// bounding sphere, radius ≤ ℓ), with R = abc / (2 |e₁ × e₂|) bounded from the grown edges and the
// shrunk area while that stays positive, else 4(ℓ + δ); the circumcentre is within that radius
// of every vertex, and the sphere (or its safe-cone part) within r + 2|offset| (max(r, offset))
// of the circumcentre, |offset| ≤ φ cot θ · r · |H3| + energyScale · |ε| from the cached factors.
// The factors cannot change meanwhile: only candidates are refreshed, and a triangle off the list
// is no candidate while the list holds (by induction over the steps). mayReach: polygon, the
// margin; bounding sphere, the centroid inside the box and a radius ≤ ℓ.
double CollisionSolver::circumsphereReach(int32_t t, const std::vector<Vec3>& x, double margin) const {
    const Tri& f = m_tris[t];
    const double delta = 2 * std::sqrt(3.0) * margin;
    const Vec3 e1 = x[f[1]] - x[f[0]], e2 = x[f[2]] - x[f[0]];
    const double a = (x[f[2]] - x[f[1]]).norm() + delta, b = e1.norm() + delta, c = e2.norm() + delta;
    double r = 4 * std::max({a, b, c});
    const double twiceArea = e1.cross(e2).norm() - delta * (b + c) - delta * delta;
    if (twiceArea > 0) r = std::min(r, a * b * c / (2 * twiceArea));
    const double offset =
        m_offsetPerRadius * r * std::abs(m_h3[t]) + m_settings.circumsphere.energyScale * std::abs(m_energy[t]);
    // The safe-cone part of the sphere (offset ≥ 0: H3, ε and the scales are) lies within
    // max(r, offset) of the circumcentre: the circumcircle's ball and the sphere's centre.
    return m_settings.safeConeOnly ? r + std::max(r, offset) : 2 * r + 2 * offset;
}

bool CollisionSolver::mayReach(int32_t t, const std::vector<Vec3>& x0, double margin, const Aabb& grownTool) const {
    const Tri& f = m_tris[t];
    // A non-finite vertex: listed, so the exact test of every step decides, as without the list.
    if (!(x0[f[0]].allFinite() && x0[f[1]].allFinite() && x0[f[2]].allFinite())) return true;
    const Vec3 lo = x0[f[0]].cwiseMin(x0[f[1]]).cwiseMin(x0[f[2]]);
    const Vec3 hi = x0[f[0]].cwiseMax(x0[f[1]]).cwiseMax(x0[f[2]]);
    double reach = 0;
    switch (m_settings.method) {
    case CollisionMethod::Polygon:
    case CollisionMethod::PolygonFeatures:
        reach = m_settings.polygonMargin;
        break;
    case CollisionMethod::Circumsphere:
        reach = circumsphereReach(t, x0, margin);
        break;
    case CollisionMethod::BoundingSphere:
        reach = (hi - lo).norm() + 2 * std::sqrt(3.0) * margin;
        break;
    }
    const Vec3 grow = Vec3::Constant(margin + reach);
    return Aabb{lo - grow, hi + grow}.overlaps(grownTool);
}

// The list holds the triangles that may reach the tool while their vertices stay within the margin
// μ. Every other triangle t gets the largest of μ, 4μ, 16μ within which it still cannot reach the
// tool, and each vertex the smallest such allowance of its unlisted triangles (listed triangles
// are tested exactly every step, so their vertices may move freely). A vertex that leaves its
// allowance brings its unlisted triangles onto the list (then tested exactly too); the list is
// made anew when the tool's box leaves the tool margin or the list has grown to twice its size.
const std::vector<int32_t>* CollisionSolver::reachList(const std::vector<Vec3>& x, const Aabb& toolBox) {
    const double margin = m_settings.reachListMargin;
    if (!(margin > 0)) return nullptr;
    const bool valid = m_reachValid && m_reachX.size() == x.size() &&
                       (toolBox.lo.array() >= m_reachTool.lo.array()).all() &&
                       (toolBox.hi.array() <= m_reachTool.hi.array()).all();
    // Grown to twice its size since it was made: made anew, tight around the tool again.
    if (valid) {
        growReachList(x);
        if (m_reach.size() <= 2 * m_reachMadeSize + 64) return &m_reach;
    }
    m_stats.reachListMade = true;
    m_stats.trianglesTested += static_cast<int>(m_tris.size());
    m_reachX = x;
    const Vec3 toolMargin = Vec3::Constant(m_settings.reachListToolMargin);
    m_reachTool = Aabb{toolBox.lo - toolMargin, toolBox.hi + toolMargin};
    m_reach.clear();
    m_inReach.assign(m_tris.size(), 0);
    m_reachAllow.assign(x.size(), std::numeric_limits<double>::infinity());
    for (int32_t t = 0; t < static_cast<int32_t>(m_tris.size()); ++t) {
        double allow = 0; // widest first: most triangles are far from the tool
        for (double tier : {16 * margin, 4 * margin, margin})
            if (!mayReach(t, x, tier, m_reachTool)) {
                allow = tier;
                break;
            }
        if (allow == 0) {
            m_reach.push_back(t);
            m_inReach[t] = 1;
            continue;
        }
        for (int32_t v : m_tris[t])
            m_reachAllow[v] = std::min(m_reachAllow[v], allow);
    }
    m_reachValid = true;
    m_reachMadeSize = m_reach.size();
    return &m_reach;
}

void CollisionSolver::growReachList(const std::vector<Vec3>& x) {
    const size_t before = m_reach.size();
    for (size_t v = 0; v < x.size(); ++v) {
        // Every component within the allowance; a NaN on either side fails the test (grows).
        if (((x[v] - m_reachX[v]).array().abs() <= m_reachAllow[v]).all()) continue;
        for (uint32_t k = m_vertexTriStart[v]; k < m_vertexTriStart[v + 1]; ++k) {
            const int32_t t = m_vertexTris[k];
            if (m_inReach[t]) continue;
            m_inReach[t] = 1;
            m_reach.push_back(t);
        }
        m_reachAllow[v] = std::numeric_limits<double>::infinity();
    }
    if (m_reach.size() == before) return;
    m_stats.reachListGrown = static_cast<int>(m_reach.size() - before);
    const auto mid = m_reach.begin() + static_cast<std::ptrdiff_t>(before);
    std::sort(mid, m_reach.end());
    std::inplace_merge(m_reach.begin(), mid, m_reach.end()); // ascending: the candidates' order
}

void CollisionSolver::beginStep(const std::vector<Vec3>& x, const ToolShape& tool, double h) {
    m_stats = CollisionStats{};
    const size_t nv = m_rest.size();
    // Only the vertices of the last step's candidates can have been pushed or touched.
    if (m_push.size() != nv) {
        m_push.assign(nv, Vec3::Zero());
        std::fill(m_touched.begin(), m_touched.end(), 0);
    } else {
        for (int32_t v : m_candVerts) {
            m_push[v].setZero();
            m_touched[v] = 0;
        }
    }
    m_candidates.clear();
    m_candVerts.clear();
    m_contactDirty = true;
    if (x.size() != nv || !(h > 0)) return;
    m_alphaTilde = m_settings.compliance / (h * h);
    m_h = h;
    const auto tb = tool.bounds();
    const Aabb toolBox{tb[0], tb[1]};
    if (toolBox.lo.allFinite() && toolBox.hi.allFinite()) {
        if (const std::vector<int32_t>* list = reachList(x, toolBox)) {
            m_stats.trianglesTested += static_cast<int>(list->size());
            for (int32_t t : *list)
                if (broadPhaseHit(t, x, toolBox)) m_candidates.push_back(t);
        } else {
            m_stats.trianglesTested = static_cast<int>(m_tris.size());
            for (int32_t t = 0; t < static_cast<int32_t>(m_tris.size()); ++t)
                if (broadPhaseHit(t, x, toolBox)) m_candidates.push_back(t);
        }
    }
    m_stats.candidates = static_cast<int>(m_candidates.size());
    // The candidates' vertices, ascending; their positions at the start of the step (the cap of
    // capCorrection: no other vertex is moved in this step).
    m_mark.resize(nv, 0);
    for (int32_t t : m_candidates)
        for (int32_t v : m_tris[t])
            if (!m_mark[v]) {
                m_mark[v] = 1;
                m_candVerts.push_back(v);
            }
    std::sort(m_candVerts.begin(), m_candVerts.end());
    m_start.resize(nv);
    for (int32_t v : m_candVerts) {
        m_mark[v] = 0;
        m_start[v] = x[v];
    }
    if (m_settings.method == CollisionMethod::Circumsphere) {
        const double delta = m_settings.circumsphere.updateThreshold;
        for (int32_t t : m_candidates) {
            const Tri& f = m_tris[t];
            const double area = 0.5 * (x[f[1]] - x[f[0]]).cross(x[f[2]] - x[f[0]]).norm();
            const double ref = m_refArea[t];
            const bool refresh = !(ref > 0) || std::abs(area / ref - 1.0) >= delta;
            if (refresh) {
                refreshFactors(t, x, area);
                ++m_stats.factorUpdates;
            }
        }
    }

    if (m_settings.method == CollisionMethod::PolygonFeatures) {
        // Each shared vertex and edge once: sorted, unique.
        m_candEdges.clear();
        m_featVerts.clear();
        for (int32_t t : m_candidates) {
            const Tri& f = m_tris[t];
            for (int k = 0; k < 3; ++k) {
                m_featVerts.push_back(f[k]);
                m_candEdges.push_back({std::min(f[k], f[(k + 1) % 3]), std::max(f[k], f[(k + 1) % 3])});
            }
        }
        std::sort(m_featVerts.begin(), m_featVerts.end());
        m_featVerts.erase(std::unique(m_featVerts.begin(), m_featVerts.end()), m_featVerts.end());
        std::sort(m_candEdges.begin(), m_candEdges.end());
        m_candEdges.erase(std::unique(m_candEdges.begin(), m_candEdges.end()), m_candEdges.end());
    }
    m_lambda.assign(constraintsPerPart() * tool.parts().size(), 0.0);
}

size_t CollisionSolver::constraintsPerPart() const {
    size_t n = m_candidates.size();
    if (m_settings.method == CollisionMethod::PolygonFeatures) n += m_candEdges.size() + m_featVerts.size();
    return n;
}

bool CollisionSolver::projectDistance(const int32_t* v, const double* b, int n, const Vec3& q, double reach,
                                      const Vec3& fallback, double& lambda, std::vector<Vec3>& x) {
    Vec3 p = Vec3::Zero();
    for (int k = 0; k < n; ++k)
        p += b[k] * x[v[k]];
    const Vec3 d = p - q;
    const double dist = d.norm();
    if (!(dist < reach)) return false;
    const Vec3 dir = dist > 1e-12 * std::max(1.0, reach) ? Vec3(d / dist) : fallback;
    if (!(dir.squaredNorm() > 0)) return false;
    double denom = m_alphaTilde;
    for (int k = 0; k < n; ++k)
        denom += m_w[v[k]] * b[k] * b[k];
    if (!(denom > 0)) return true;
    const double dl = (-(dist - reach) - m_alphaTilde * lambda) / denom;
    lambda += dl;
    for (int k = 0; k < n; ++k)
        applyCorrection(v[k], m_w[v[k]] * b[k] * dl * dir, x);
    return true;
}

int CollisionSolver::iterateFeatures(std::vector<Vec3>& x, const std::vector<Capsule>& parts) {
    // [Eri04] primitive tests, one constraint type after the other: faces, edges, vertices.
    const size_t np = parts.size(), nf = m_candidates.size(), ne = m_candEdges.size();
    const double reachExtra = m_settings.polygonMargin;
    constexpr double kInside = 1e-9; // a face contact only where the closest point is interior
    int contacts = 0;
    for (size_t i = 0; i < nf; ++i) {
        const Tri& f = m_tris[m_candidates[i]];
        const Vec3 nt = (x[f[1]] - x[f[0]]).cross(x[f[2]] - x[f[0]]);
        if (!(nt.squaredNorm() > 0)) continue;
        for (size_t p = 0; p < np; ++p) {
            const Capsule& c = parts[p];
            const SegmentTrianglePair st = closestPointsSegmentTriangle(c.a, c.b, x[f[0]], x[f[1]], x[f[2]]);
            const Vec3& bary = st.onTriangle.bary;
            if (!(bary.minCoeff() > kInside)) continue; // an edge or vertex feature: tested below
            const double b[3] = {bary[0], bary[1], bary[2]};
            contacts += projectDistance(f.data(), b, 3, st.onSegment, c.radius + reachExtra, -nt.normalized(),
                                        m_lambda[i * np + p], x);
        }
    }
    for (size_t e = 0; e < ne; ++e) {
        const auto& ed = m_candEdges[e];
        for (size_t p = 0; p < np; ++p) {
            const Capsule& c = parts[p];
            const SegmentPair sp = closestPointsSegments(x[ed[0]], x[ed[1]], c.a, c.b);
            const double b[2] = {1 - sp.s, sp.s};
            contacts += projectDistance(ed.data(), b, 2, sp.onQ, c.radius + reachExtra, Vec3::Zero(),
                                        m_lambda[(nf + e) * np + p], x);
        }
    }
    for (size_t k = 0; k < m_featVerts.size(); ++k) {
        const int32_t v = m_featVerts[k];
        for (size_t p = 0; p < np; ++p) {
            const Capsule& c = parts[p];
            const Vec3 q = c.a + closestParameterOnSegment(x[v], c.a, c.b) * (c.b - c.a);
            const double b[1] = {1.0};
            contacts +=
                projectDistance(&v, b, 1, q, c.radius + reachExtra, Vec3::Zero(), m_lambda[(nf + ne + k) * np + p], x);
        }
    }
    return contacts;
}

bool CollisionSolver::projectSphere(int32_t t, const Sphere& s, const Capsule& c, double& lambda,
                                    std::vector<Vec3>& x) {
    const AxisPoint ap = closestAxisPoint(c, s.centre);
    const double pen = s.radius + c.radius - ap.distance;
    if (!(pen > 0)) return false;
    // A tool that meets the sphere outside its safe cone touches the part of the sphere that
    // lies inside the tissue (under the neighbouring triangles), not this triangle's surface.
    if (m_settings.safeConeOnly && !s.inSafeCone(ap.onAxis)) return false;
    const Tri& f = m_tris[t];
    Vec3 dir = ap.direction;
    if (ap.distance <= 1e-12 * std::max(1.0, s.radius)) {
        // Sphere centre on the axis: push the triangle into the tissue (against its normal).
        const Vec3 n = (x[f[1]] - x[f[0]]).cross(x[f[2]] - x[f[0]]);
        if (n.squaredNorm() > 0) dir = -n.normalized();
    }
    // Sphere translation (targets x'_i = x_i + move), at most one tool radius per projection:
    // a sphere grows with its stretched triangle, and an uncapped push would feed that growth.
    const Vec3 move = std::min(pen, c.radius) * dir;
    const std::array<Vec3, 3> xs = {x[f[0]], x[f[1]], x[f[2]]};
    const std::array<Vec3, 3> target = {xs[0] + move, xs[1] + move, xs[2] + move};
    std::array<Vec3, 3> grad;
    const double C = unifiedTriangleConstraint(xs, target, m_settings.squaredForm, &grad);
    double denom = m_alphaTilde;
    for (int k = 0; k < 3; ++k)
        denom += m_w[f[k]] * grad[k].squaredNorm();
    if (!(denom > 0) || !(C > 0)) return true;
    const double dl = (-C - m_alphaTilde * lambda) / denom;
    lambda += dl;
    for (int k = 0; k < 3; ++k)
        applyCorrection(f[k], m_w[f[k]] * dl * grad[k], x);
    return true;
}

bool CollisionSolver::projectPolygon(int32_t t, const Capsule& c, double& lambda, std::vector<Vec3>& x) {
    const Tri& f = m_tris[t];
    const SegmentTrianglePair st = closestPointsSegmentTriangle(c.a, c.b, x[f[0]], x[f[1]], x[f[2]]);
    const double reach = c.radius + m_settings.polygonMargin;
    if (!(st.distance < reach)) return false;
    // C = n·(Σ b_i x_i − q) − reach with n the unit direction from the axis point: the distance
    // form of pointTriangleConstraint, ∇_i C = b_i n; −N when the axis pierces the triangle.
    const Vec3 nt = (x[f[1]] - x[f[0]]).cross(x[f[2]] - x[f[0]]);
    const Vec3 fallback = nt.squaredNorm() > 0 ? Vec3(-nt.normalized()) : Vec3::Zero();
    const Vec3& bary = st.onTriangle.bary;
    const double b[3] = {bary[0], bary[1], bary[2]};
    projectDistance(f.data(), b, 3, st.onSegment, reach, fallback, lambda, x);
    return true;
}

void CollisionSolver::applyCorrection(int32_t v, const Vec3& delta, std::vector<Vec3>& x) {
    const Vec3 before = x[v];
    x[v] += delta;
    capCorrection(v, x);
    const Vec3 dx = x[v] - before;
    m_push[v] += dx;
    m_stats.maxCorrection = std::max(m_stats.maxCorrection, dx.norm());
    m_touched[v] = 1;
}

void CollisionSolver::capCorrection(int32_t v, std::vector<Vec3>& x) const {
    const Vec3 total = x[v] - m_start[v];
    const double len = total.norm(), cap = m_settings.maxCorrectionPerStep;
    if (len > cap) x[v] = m_start[v] + (cap / len) * total;
}

int CollisionSolver::iterate(std::vector<Vec3>& x, const ToolShape& tool) {
    if (x.size() != m_rest.size()) return 0;
    const auto& parts = tool.parts();
    if (m_lambda.size() != constraintsPerPart() * parts.size()) return 0;
    int contacts = 0;
    m_stats.maxCorrection = 0;
    if (m_settings.method == CollisionMethod::PolygonFeatures) {
        contacts = iterateFeatures(x, parts);
        m_stats.contacts = contacts;
        if (contacts) m_contactDirty = true;
        return contacts;
    }
    for (size_t i = 0; i < m_candidates.size(); ++i) {
        const int32_t t = m_candidates[i];
        if (m_settings.method == CollisionMethod::Polygon) {
            for (size_t p = 0; p < parts.size(); ++p)
                contacts += projectPolygon(t, parts[p], m_lambda[i * parts.size() + p], x);
        } else {
            for (size_t p = 0; p < parts.size(); ++p) {
                const Sphere s = triangleSphere(t, x); // current vertices, cached factors
                contacts += projectSphere(t, s, parts[p], m_lambda[i * parts.size() + p], x);
            }
        }
    }
    m_stats.contacts = contacts;
    if (contacts) m_contactDirty = true;
    return contacts;
}

void CollisionSolver::beginStep(const XpbdParticles& particles, size_t offset, const ToolShape& tool, double h) {
    const size_t nv = m_rest.size();
    m_viewValid = offset <= particles.size() && nv <= particles.size() - offset;
    if (!m_viewValid) {
        beginStep(std::vector<Vec3>{}, tool, h); // size mismatch: an empty step
        return;
    }
    m_x.resize(nv);
    for (size_t v = 0; v < nv; ++v)
        m_x[v] = particles.position(offset + v);
    beginStep(m_x, tool, h);
}

int CollisionSolver::iterate(XpbdParticles& particles, size_t offset, const ToolShape& tool) {
    if (!m_viewValid || m_candidates.empty() || offset > particles.size() || m_rest.size() > particles.size() - offset)
        return 0;
    for (int32_t v : m_candVerts)
        m_x[v] = particles.position(offset + v);
    const int contacts = iterate(m_x, tool);
    if (contacts)
        for (int32_t v : m_candVerts)
            if (particles.inverseMass(offset + v) != 0) particles.setPosition(offset + v, m_x[v]);
    return contacts;
}

Vec3 CollisionSolver::contactForce() const {
    Vec3 f = Vec3::Zero();
    if (!(m_h > 0) || m_push.size() != m_w.size() || m_touched.size() != m_w.size()) return f;
    auto add = [&](size_t v) {
        if (m_touched[v] && m_w[v] > 0) f += m_push[v] / m_w[v];
    };
    if (m_viewValid) // particle-view step: only the candidates' vertices can have moved
        for (int32_t v : m_candVerts)
            add(static_cast<size_t>(v));
    else
        for (size_t v = 0; v < m_push.size(); ++v)
            add(v);
    return f / (m_h * m_h);
}

int CollisionSolver::endStep(XpbdParticles& particles, size_t offset) {
    if (!m_viewValid || !particles.hasVelocities() || offset > particles.size() ||
        m_rest.size() > particles.size() - offset || m_push.size() != m_rest.size())
        return 0;
    int changed = 0;
    for (int32_t v : m_candVerts) {
        if (!m_touched[v] || particles.inverseMass(offset + v) == 0) continue;
        const double len = m_push[v].norm();
        if (!(len > 0)) continue;
        const Vec3 n = m_push[v] / len;
        Vec3 vel = particles.velocity(offset + v);
        const double vn = vel.dot(n);
        if (vn > 0) {
            vel -= vn * n;
            particles.setVelocity(offset + v, vel);
            ++changed;
        }
    }
    return changed;
}

XpbdIterationHook makeCollisionHook(CollisionSolver& collision, const ToolShape& tool, size_t particleOffset) {
    return [&collision, &tool, particleOffset](XpbdParticles& p, const XpbdIterationInfo& info) {
        if (info.velocityPass) {
            collision.endStep(p, particleOffset);
            return;
        }
        if (info.iteration == 0) collision.beginStep(p, particleOffset, tool, info.h);
        collision.iterate(p, particleOffset, tool);
    };
}

const std::vector<int32_t>& CollisionSolver::contactVertices() const {
    if (m_contactDirty) {
        m_contactVerts.clear();
        for (size_t v = 0; v < m_touched.size(); ++v)
            if (m_touched[v]) m_contactVerts.push_back(static_cast<int32_t>(v));
        m_contactDirty = false;
    }
    return m_contactVerts;
}

bool collisionVelocityUpdate(const std::vector<Vec3>& before, const std::vector<Vec3>& after, std::vector<Vec3>& v) {
    bool finite = true;
    for (size_t i = 0; i < after.size() && i < before.size() && i < v.size(); ++i) {
        const Vec3 d = after[i] - before[i];
        const double len = d.norm();
        if (len > 0) {
            const Vec3 n = d / len;
            const double vn = v[i].dot(n);
            if (vn < 0) v[i] -= vn * n;
        }
        finite = finite && after[i].allFinite() && v[i].allFinite();
    }
    return finite;
}

CollisionFrameResult stepWithCollision(XpbdSolver& solver, CollisionSolver& collision, ToolShape& tool,
                                       const ToolShape::Pose& from, const ToolShape::Pose& to, int substeps,
                                       int iterations) {
    CollisionFrameResult r;
    const double h = solver.settings().dt;
    const std::vector<Vec3> start = solver.positions();
    std::vector<Vec3> x, v;
    substeps = std::max(1, substeps);
    for (int s = 1; s <= substeps; ++s) {
        tool.setPose(interpolatePose(from, to, static_cast<double>(s) / substeps));
        const StepStats st = solver.step();
        if (!st.finite) r.finite = false;
        x = solver.positions();
        collision.beginStep(x, tool, h);
        for (int k = 0; k < iterations; ++k)
            collision.iterate(x, tool);
        r.last = collision.stats();
        if (collision.stats().candidates == 0) continue;
        v = solver.velocities();
        const bool finite = collisionVelocityUpdate(solver.positions(), x, v);
        if (!finite) {
            r.finite = false;
            continue;
        }
        try {
            solver.setState(x, v);
        } catch (const std::exception&) {
            r.finite = false;
        }
    }
    const std::vector<Vec3>& end = solver.positions();
    for (size_t i = 0; i < end.size() && i < start.size(); ++i)
        r.maxDisplacement = std::max(r.maxDisplacement, (end[i] - start[i]).norm());
    return r;
}

} // namespace viscera::sim
