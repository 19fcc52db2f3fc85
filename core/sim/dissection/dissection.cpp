#include "sim/dissection/dissection.hpp"

#include "sim/collision/distance.hpp"
#include "sim/util/format.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace viscera::sim {
namespace {

std::string checkTissue(const TissueDissectionParams& t) {
    if (!std::isfinite(t.ignition) || !(t.ignition > 0))
        return "ignition is " + formatNumber(t.ignition) + " (must be finite and > 0)";
    if (!std::isfinite(t.conductivity) || !(t.conductivity > 0))
        return "conductivity is " + formatNumber(t.conductivity) + " (must be finite and > 0)";
    for (int a = 0; a < 3; ++a)
        if (!(t.shrink[a] >= 0.01 && t.shrink[a] <= 10.0))
            return "shrink[" + std::to_string(a) + "] is " + formatNumber(t.shrink[a]) + " (must be in [0.01, 10])";
    return {};
}

/// Distance from the tool centre at time t ∈ [0, 1] of the frame to segment (a, b).
double distanceAt(double t, const Vec3& c0, const Vec3& c1, const Vec3& a, const Vec3& b) {
    const Vec3 c = c0 + t * (c1 - c0);
    const double s = closestParameterOnSegment(c, a, b);
    return (c - (a + s * (b - a))).norm();
}

/// Fraction of the frame during which the sphere (radius r) moving from c0 to c1 overlaps segment
/// (a, b). d(t) is convex, so the overlap is the interval around the closest approach where
/// d ≤ r; its ends are found by bisection (60 halvings: below double resolution).
double overlapFraction(const Vec3& c0, const Vec3& c1, double r, const Vec3& a, const Vec3& b) {
    if ((c1 - c0).squaredNorm() == 0.0) return distanceAt(0, c0, c1, a, b) <= r ? 1.0 : 0.0;
    const SegmentPair sp = closestPointsSegments(c0, c1, a, b);
    const double tm = sp.s;
    if (distanceAt(tm, c0, c1, a, b) > r) return 0.0;
    double t0 = 0, t1 = 1;
    if (distanceAt(0, c0, c1, a, b) > r) {
        double lo = 0, hi = tm; // d(lo) > r ≥ d(hi)
        for (int i = 0; i < 60 && hi - lo > 0; ++i) {
            const double m = 0.5 * (lo + hi);
            (distanceAt(m, c0, c1, a, b) > r ? lo : hi) = m;
        }
        t0 = hi;
    }
    if (distanceAt(1, c0, c1, a, b) > r) {
        double lo = tm, hi = 1; // d(lo) ≤ r < d(hi)
        for (int i = 0; i < 60 && hi - lo > 0; ++i) {
            const double m = 0.5 * (lo + hi);
            (distanceAt(m, c0, c1, a, b) > r ? hi : lo) = m;
        }
        t1 = lo;
    }
    return std::clamp(t1 - t0, 0.0, 1.0);
}

Vec3 anyPerpendicular(const Vec3& n) {
    const Vec3 axis = std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
    return n.cross(axis).normalized();
}

} // namespace

std::unique_ptr<Dissection> Dissection::create(const DissectionDesc& d) {
    const std::string where = "sim::Dissection::create(): ";
    if (!d.system) throw std::invalid_argument(where + "system is null");
    if (!d.fascia && !d.fat) throw std::invalid_argument(where + "no layer (fascia and fat meshes are both null)");
    if (auto why = validate(d.grid); !why.empty()) throw std::invalid_argument(where + "grid: " + why);
    if (!std::isfinite(d.referenceTime) || !(d.referenceTime > 0))
        throw std::invalid_argument(where + "referenceTime is " + formatNumber(d.referenceTime) + " (must be > 0)");
    std::unique_ptr<Dissection> out(new Dissection(d.grid));
    out->m_sys = d.system;
    out->m_tref = d.referenceTime;
    const XpbdSystem& sys = *d.system;
    if (d.fascia) {
        const std::string label = where + "fascia: ";
        if (auto why = checkTissue(d.fasciaTissue); !why.empty()) throw std::invalid_argument(label + why);
        if (d.surface >= sys.surfaceCount())
            throw std::invalid_argument(label + "surface " + std::to_string(d.surface) + " does not exist");
        if (d.fascia->vertexCount() != sys.surfacePositions(d.surface).size() ||
            d.fascia->triangleCount() != sys.triangleCount(d.surface))
            throw std::invalid_argument(label + "mesh has " + std::to_string(d.fascia->vertexCount()) +
                                        " vertices and " + std::to_string(d.fascia->triangleCount()) +
                                        " triangles, surface '" + sys.surfaceName(d.surface) + "' has " +
                                        std::to_string(sys.surfacePositions(d.surface).size()) + " and " +
                                        std::to_string(sys.triangleCount(d.surface)));
        Layer L;
        L.tets = false;
        L.body = d.surface;
        L.tissue = d.fasciaTissue;
        L.edges = EdgeStructure::fromTriangles(d.fascia->triangles(), d.fascia->vertexCount());
        for (const Tri& t : d.fascia->triangles())
            L.prims.push_back({t[0], t[1], t[2], -1});
        out->m_fascia = std::move(L);
    }
    if (d.fat) {
        const std::string label = where + "fat: ";
        if (auto why = checkTissue(d.fatTissue); !why.empty()) throw std::invalid_argument(label + why);
        if (d.tetBody >= sys.tetBodyCount())
            throw std::invalid_argument(label + "tet body " + std::to_string(d.tetBody) + " does not exist");
        if (d.fat->vertexCount() != sys.tetPositions(d.tetBody).size() || d.fat->tetCount() != sys.tetCount(d.tetBody))
            throw std::invalid_argument(
                label + "mesh has " + std::to_string(d.fat->vertexCount()) + " vertices and " +
                std::to_string(d.fat->tetCount()) + " tets, body '" + sys.tetBodyName(d.tetBody) + "' has " +
                std::to_string(sys.tetPositions(d.tetBody).size()) + " and " + std::to_string(sys.tetCount(d.tetBody)));
        Layer L;
        L.tets = true;
        L.body = d.tetBody;
        L.tissue = d.fatTissue;
        L.edges = EdgeStructure::fromTets(d.fat->tets(), d.fat->vertexCount());
        L.liveTets.assign(d.fat->vertexCount(), 0);
        for (const Tet& t : d.fat->tets()) {
            L.prims.push_back({t[0], t[1], t[2], t[3]});
            for (int32_t v : t)
                ++L.liveTets[static_cast<size_t>(v)];
        }
        out->m_fat = std::move(L);
        if (d.fat->level() >= 3) {
            out->m_hasFatBoundary = true;
            for (int32_t f : d.fat->boundaryHalfFacets())
                out->m_fatBoundaryTet.push_back(TetMesh::cellOf(f));
        }
    }
    for (std::optional<Layer>* L : {&out->m_fascia, &out->m_fat})
        if (L->has_value()) {
            (*L)->heat.assign((*L)->edges.edgeCount(), 0.0);
            (*L)->shrunk.assign((*L)->edges.primitiveCount(), 0);
        }
    return out;
}

DissectionFrameStats Dissection::update(const EnergyTool& tool, double dt) {
    const std::string where = "sim::Dissection::update(): ";
    if (!tool.centre.allFinite() || !std::isfinite(tool.radius) || !std::isfinite(tool.temperature))
        throw std::invalid_argument(where + "tool centre, radius or temperature is not finite");
    if (!(tool.radius > 0))
        throw std::invalid_argument(where + "tool radius is " + formatNumber(tool.radius) + " (must be > 0)");
    if (tool.temperature < -273.15)
        throw std::invalid_argument(where + "tool temperature is " + formatNumber(tool.temperature) +
                                    " (must be >= -273.15)");
    if (!std::isfinite(dt) || !(dt > 0))
        throw std::invalid_argument(where + "dt is " + formatNumber(dt) + " (must be > 0)");

    DissectionFrameStats st;
    st.heatSubsteps = tool.energized ? m_heat.advance({tool.centre, tool.radius, tool.temperature}, dt)
                                     : m_heat.advanceUnheated(tool.centre, dt);
    st.gridMin = m_heat.minTemperature();
    st.gridMax = m_heat.maxTemperature();
    const Vec3 from = m_prevCentre.value_or(tool.centre);
    if (m_fascia) updateLayer(*m_fascia, tool, from, dt, st.fascia);
    if (m_fat) updateLayer(*m_fat, tool, from, dt, st.fat);
    m_prevCentre = tool.centre;
    return st;
}

void Dissection::updateLayer(Layer& L, const EnergyTool& tool, const Vec3& from, double dt, DissectionLayerStats& st) {
    const std::vector<Vec3>& x = L.tets ? m_sys->tetPositions(L.body) : m_sys->surfacePositions(L.body);
    st.vertexCount = x.size();
    EdgeStructure& E = L.edges;
    std::vector<int32_t> ignite;
    if (tool.energized) {
        const double r = tool.radius;
        const Vec3 lo = from.cwiseMin(tool.centre) - Vec3::Constant(r);
        const Vec3 hi = from.cwiseMax(tool.centre) + Vec3::Constant(r);
        const double gain = L.tissue.conductivity * dt / m_tref;
        for (size_t e = 0; e < E.edgeCount(); ++e) {
            if (E.isDissected(e)) continue;
            const Vec3& a = x[E.edge(e)[0]];
            const Vec3& b = x[E.edge(e)[1]];
            if ((a.cwiseMax(b).array() < lo.array()).any() || (a.cwiseMin(b).array() > hi.array()).any()) continue;
            const double f = overlapFraction(from, tool.centre, r, a, b);
            if (!(f > 0)) continue;
            ++st.edgesTouched;
            // eq. 5.11, accumulated: τ_e += ξ (u_a + u_b)/2 · δt / t_ref.
            L.heat[e] += gain * f * 0.5 * (m_heat.temperatureAt(a) + m_heat.temperatureAt(b));
            if (L.heat[e] >= L.tissue.ignition) ignite.push_back(static_cast<int32_t>(e));
        }
    }
    cutEdges(L, ignite, &tool, st);
}

void Dissection::cutEdges(Layer& L, const std::vector<int32_t>& edges, const EnergyTool* shrinkBy,
                          DissectionLayerStats& st) {
    EdgeStructure& E = L.edges;
    const std::vector<Vec3>& x = L.tets ? m_sys->tetPositions(L.body) : m_sys->surfacePositions(L.body);
    m_newlyCut.clear();
    Vec3 sum = Vec3::Zero();
    for (int32_t e : edges)
        if (E.dissect(static_cast<size_t>(e), &m_newlyCut)) {
            ++st.edgesCut;
            sum += 0.5 * (x[E.edge(static_cast<size_t>(e))[0]] + x[E.edge(static_cast<size_t>(e))[1]]);
        }
    if (st.edgesCut > 0) st.cutCentre = sum / static_cast<double>(st.edgesCut);
    st.primitivesCut = m_newlyCut.size();
    for (int32_t p : m_newlyCut) {
        if (!L.tets) {
            m_sys->setTriangleActive(L.body, p, false);
            continue;
        }
        m_sys->setTetActive(L.body, p, false);
        // a node whose tets are all cut belongs to no tissue any more: it stays where it was cut
        // (held), not falling out of the scene on its own
        for (int32_t v : L.prims[static_cast<size_t>(p)])
            if (--L.liveTets[static_cast<size_t>(v)] == 0) m_sys->holdTetNode(L.body, static_cast<size_t>(v));
    }
    if (shrinkBy && L.tissue.shrinkage && !(L.tissue.shrink.array() == 1.0).all())
        for (int32_t p : m_newlyCut)
            for (int32_t e : E.edgesOf(p))
                for (int32_t q : E.primitivesOf(e)) {
                    if (E.isCut(q) || L.shrunk[q]) continue;
                    L.shrunk[q] = 1;
                    const Mat3 Fs = shrinkFrame(L, x, q, *shrinkBy);
                    try {
                        if (L.tets)
                            m_sys->setTetRestShape(L.body, q, Fs);
                        else
                            m_sys->setTriangleRestShape(L.body, q, Fs);
                        ++st.primitivesShrunk;
                    } catch (const std::invalid_argument&) {
                        // A degenerate shrunk shape: keep the element's rest shape.
                    }
                }
    st.totalEdgesCut = E.dissectedEdgeCount();
    st.totalPrimitivesCut = E.cutPrimitiveCount();
    for (size_t e = 0; e < E.edgeCount(); ++e)
        if (!E.isDissected(e)) st.maxEdgeHeat = std::max(st.maxEdgeHeat, L.heat[e]);
}

DissectionFrameStats Dissection::shear(const Vec3& clevis, const Vec3& tipA, const Vec3& tipB, double radius) {
    const std::string where = "sim::Dissection::shear(): ";
    if (!clevis.allFinite() || !tipA.allFinite() || !tipB.allFinite() || !std::isfinite(radius))
        throw std::invalid_argument(where + "blade points or radius not finite");
    if (!(radius > 0)) throw std::invalid_argument(where + "radius is " + formatNumber(radius) + " (must be > 0)");
    DissectionFrameStats st;
    st.gridMin = m_heat.minTemperature();
    st.gridMax = m_heat.maxTemperature();
    const bool wedge = (tipA - tipB).norm() > 1e-9;
    const Vec3 lo = clevis.cwiseMin(tipA).cwiseMin(tipB) - Vec3::Constant(radius);
    const Vec3 hi = clevis.cwiseMax(tipA).cwiseMax(tipB) + Vec3::Constant(radius);
    for (std::optional<Layer>* Lp : {&m_fascia, &m_fat}) {
        if (!Lp->has_value()) continue;
        Layer& L = **Lp;
        DissectionLayerStats& ls = Lp == &m_fascia ? st.fascia : st.fat;
        const std::vector<Vec3>& x = L.tets ? m_sys->tetPositions(L.body) : m_sys->surfacePositions(L.body);
        ls.vertexCount = x.size();
        std::vector<int32_t> snipped;
        for (size_t e = 0; e < L.edges.edgeCount(); ++e) {
            if (L.edges.isDissected(e)) continue;
            const Vec3& p = x[L.edges.edge(e)[0]];
            const Vec3& q = x[L.edges.edge(e)[1]];
            if ((p.cwiseMax(q).array() < lo.array()).any() || (p.cwiseMin(q).array() > hi.array()).any()) continue;
            const bool near = wedge ? closestPointsSegmentTriangle(p, q, clevis, tipA, tipB).distance <= radius
                                    : overlapFraction(clevis, tipA, radius, p, q) > 0;
            if (!near) continue;
            ++ls.edgesTouched;
            snipped.push_back(static_cast<int32_t>(e));
        }
        cutEdges(L, snipped, nullptr, ls); // a cold cut: no heat, no shrinking
        if (ls.edgesCut > 0) st.swept = std::array<Vec3, 3>{clevis, tipA, tipB};
    }
    return st;
}

Mat3 Dissection::shrinkFrame(const Layer& L, const std::vector<Vec3>& x, size_t p, const EnergyTool& tool) const {
    const auto& e = L.prims[p];
    const int nv = L.tets ? 4 : 3;
    Vec3 centre = Vec3::Zero();
    for (int k = 0; k < nv; ++k)
        centre += x[e[k]];
    centre /= nv;
    // Face normal Nf: the triangle's, or that of the tet face nearest the tool centre.
    Vec3 nf = Vec3::UnitZ();
    if (!L.tets) {
        nf = (x[e[1]] - x[e[0]]).cross(x[e[2]] - x[e[0]]);
    } else {
        double best = std::numeric_limits<double>::infinity();
        for (int k = 0; k < 4; ++k) { // face opposite vertex k
            const Vec3& a = x[e[(k + 1) % 4]];
            const Vec3& b = x[e[(k + 2) % 4]];
            const Vec3& c = x[e[(k + 3) % 4]];
            const double d = ((a + b + c) / 3.0 - tool.centre).squaredNorm();
            if (d < best) {
                best = d;
                nf = (b - a).cross(c - a);
            }
        }
    }
    // Contact normal: ∇f at x_c = c + r (centre − c)/|centre − c| is (centre − c)/|centre − c|.
    Vec3 nc = centre - tool.centre;
    const double nfLen = nf.norm();
    nf = nfLen > 0 && std::isfinite(nfLen) ? Vec3(nf / nfLen) : Vec3(Vec3::UnitZ());
    const double ncLen = nc.norm();
    nc = ncLen > 1e-12 && std::isfinite(ncLen) ? Vec3(nc / ncLen) : nf;
    Vec3 na = nf.cross(nc);
    na = na.norm() > 1e-9 ? Vec3(na.normalized()) : anyPerpendicular(nc);
    const Vec3 nb = nc.cross(na);
    // Fs = Rᵀ diag(Sx, Sy, Sz) R with R's rows (Nc, Na, Nb).
    const Vec3& S = L.tissue.shrink;
    return S.x() * nc * nc.transpose() + S.y() * na * na.transpose() + S.z() * nb * nb.transpose();
}

const EdgeStructure& Dissection::fasciaEdges() const {
    if (!m_fascia) throw std::logic_error("sim::Dissection::fasciaEdges(): no fascia layer");
    return m_fascia->edges;
}

const EdgeStructure& Dissection::fatEdges() const {
    if (!m_fat) throw std::logic_error("sim::Dissection::fatEdges(): no fat layer");
    return m_fat->edges;
}

const std::vector<double>& Dissection::fasciaEdgeHeat() const {
    if (!m_fascia) throw std::logic_error("sim::Dissection::fasciaEdgeHeat(): no fascia layer");
    return m_fascia->heat;
}

const std::vector<double>& Dissection::fatEdgeHeat() const {
    if (!m_fat) throw std::logic_error("sim::Dissection::fatEdgeHeat(): no fat layer");
    return m_fat->heat;
}

void Dissection::fasciaFaceMaskInto(std::vector<uint8_t>& out) const {
    fasciaEdges().intactMaskInto(out);
}

namespace {
/// Per vertex: the largest τ_e of its edges over the ignition temperature, 1 on a dissected edge.
void vertexHeatInto(const EdgeStructure& E, const std::vector<double>& heat, double ignition, std::vector<float>& out) {
    out.assign(E.vertexCount(), 0.0f);
    for (size_t e = 0; e < E.edgeCount(); ++e) {
        const double h = E.isDissected(e) ? 1.0 : std::clamp(heat[e] / ignition, 0.0, 1.0);
        if (!(h > 0)) continue;
        for (int32_t v : E.edge(e))
            out[static_cast<size_t>(v)] = std::max(out[static_cast<size_t>(v)], static_cast<float>(h));
    }
}
} // namespace

void Dissection::fasciaVertexHeatInto(std::vector<float>& out) const {
    vertexHeatInto(fasciaEdges(), m_fascia->heat, m_fascia->tissue.ignition, out);
}

void Dissection::fatVertexHeatInto(std::vector<float>& out) const {
    vertexHeatInto(fatEdges(), m_fat->heat, m_fat->tissue.ignition, out);
}

void Dissection::fatTetMaskInto(std::vector<uint8_t>& out) const {
    fatEdges().intactMaskInto(out);
}

void Dissection::fatBoundaryMaskInto(std::vector<uint8_t>& out) const {
    const EdgeStructure& E = fatEdges();
    if (!m_hasFatBoundary)
        throw std::logic_error("sim::Dissection::fatBoundaryMaskInto(): the fat mesh had no boundary at create(); "
                               "call TetMesh::requireLevel(3) before Dissection::create()");
    out.resize(m_fatBoundaryTet.size());
    for (size_t k = 0; k < out.size(); ++k)
        out[k] = E.isCut(static_cast<size_t>(m_fatBoundaryTet[k])) ? 0 : 1;
}

} // namespace viscera::sim
