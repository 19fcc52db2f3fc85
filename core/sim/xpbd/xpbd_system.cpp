#include "sim/xpbd/xpbd_system.hpp"

#include "sim/util/error.hpp"
#include "sim/util/format.hpp"
#include "sim/xpbd/coupling.hpp"
#include "sim/xpbd/detail/blocks.hpp"
#include "sim/xpbd/detail/engine.hpp"
#include "sim/xpbd/detail/thread_pool.hpp"
#include "sim/xpbd/membrane.hpp"

#include <Eigen/Dense>

#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace viscera::sim {
namespace {

struct Failer {
    const std::string& where;
    [[noreturn]] void operator()(const std::string& label, const std::string& why) const {
        throw PreconditionError(where, label + why);
    }
};

void checkFixed(const std::vector<int32_t>& fixed, size_t nv, const std::string& label, const Failer& fail) {
    for (int32_t f : fixed)
        if (f < 0 || static_cast<size_t>(f) >= nv)
            fail(label,
                 "fixed node " + std::to_string(f) + " is out of range (mesh has " + std::to_string(nv) + " vertices)");
}

/// Empty (all 1) or one weight per vertex, each positive and finite (it divides compliances).
void checkNodeWeights(const std::vector<double>& w, size_t nv, const std::string& label, const Failer& fail) {
    if (w.empty()) return;
    if (w.size() != nv)
        fail(label, "node weights: " + std::to_string(w.size()) + " given for " + std::to_string(nv) + " vertices");
    for (size_t i = 0; i < nv; ++i)
        if (!std::isfinite(w[i]) || w[i] <= 0)
            fail(label,
                 "node weight " + std::to_string(i) + " is " + formatNumber(w[i]) + " (must be positive and finite)");
}

void checkLimits(const std::vector<StrainLimit>& limits, int dim, const std::vector<int32_t>& elems, size_t count,
                 const char* elemName, const std::string& label, const Failer& fail) {
    if (limits.empty()) fail(label, "strain limits: no limit given");
    for (size_t k = 0; k < limits.size(); ++k)
        if (auto why = validate(limits[k], dim); !why.empty())
            fail(label, "strain limit " + std::to_string(k) + ": " + why);
    for (int32_t e : elems)
        if (e < 0 || static_cast<size_t>(e) >= count)
            fail(label, std::string("strain limits: ") + elemName + " " + std::to_string(e) + " is out of range (" +
                            std::to_string(count) + " " + elemName + "s)");
}

std::vector<int32_t> allOr(const std::vector<int32_t>& subset, size_t count) {
    if (!subset.empty()) return subset;
    std::vector<int32_t> all(count);
    for (size_t i = 0; i < count; ++i)
        all[i] = static_cast<int32_t>(i);
    return all;
}

} // namespace

XpbdSystem::XpbdSystem() : m_engine(std::make_unique<detail::Engine>()) {}
XpbdSystem::~XpbdSystem() = default;

std::unique_ptr<XpbdSystem> XpbdSystem::create(const XpbdSystemDesc& desc, const XpbdSettings& settings) {
    return build(desc, settings, "sim::XpbdSystem::create(): ", false);
}

std::unique_ptr<XpbdSystem> XpbdSystem::build(const XpbdSystemDesc& desc, const XpbdSettings& settings,
                                              const std::string& where, bool singleBody) {
    const Failer fail{where};
    if (auto why = validate(settings); !why.empty()) fail("", why);
    if (desc.tetBodies.empty() && desc.surfaces.empty()) fail("", "the system has no body");
    std::unique_ptr<XpbdSystem> sys(new XpbdSystem());
    sys->m_settings = settings;
    detail::Engine& eng = *sys->m_engine;

    auto tetLabel = [&](size_t b) {
        return singleBody ? std::string() : "tet body " + std::to_string(b) + " ('" + desc.tetBodies[b].name + "'): ";
    };
    auto surfLabel = [&](size_t s) { return "surface " + std::to_string(s) + " ('" + desc.surfaces[s].name + "'): "; };

    // Particle layout: tet bodies, then surfaces.
    std::vector<int32_t> tetFirst, surfFirst;
    int32_t next = 0;
    for (size_t b = 0; b < desc.tetBodies.size(); ++b) {
        if (!desc.tetBodies[b].mesh) fail(tetLabel(b), "mesh is null");
        tetFirst.push_back(next);
        next += static_cast<int32_t>(desc.tetBodies[b].mesh->vertexCount());
    }
    std::vector<std::vector<Vec3>> surfX(desc.surfaces.size());
    for (size_t s = 0; s < desc.surfaces.size(); ++s) {
        if (!desc.surfaces[s].mesh) fail(surfLabel(s), "mesh is null");
        surfFirst.push_back(next);
        next += static_cast<int32_t>(desc.surfaces[s].mesh->vertexCount());
        surfX[s] = desc.surfaces[s].mesh->positions();
    }

    // ---- tet bodies ----
    std::vector<std::unique_ptr<detail::Block>> strainBlocks;
    std::vector<size_t> strainBlockBody; // dissection: tet body of each strain block
    for (size_t b = 0; b < desc.tetBodies.size(); ++b) {
        const TetBodyDesc& d = desc.tetBodies[b];
        const std::string label = tetLabel(b);
        const TetMesh& mesh = *d.mesh;
        if (!d.model) fail(label, "constraint model is null");
        const int count = d.model->count();
        if (count < 1 || count > kMaxTetConstraints)
            fail(label, "constraint model '" + d.model->name() + "' has " + std::to_string(count) +
                            " constraints per tet (supported: 1 or 2)");
        const auto alpha = d.model->compliance();
        for (int k = 0; k < count; ++k)
            if (!std::isfinite(alpha[k]) || alpha[k] < 0)
                fail(label, "constraint model '" + d.model->name() + "' has compliance " + formatNumber(alpha[k]) +
                                " (must be finite and >= 0)");
        if (!std::isfinite(d.density) || d.density <= 0) fail(label, "density must be positive and finite");
        const size_t nv = mesh.vertexCount();
        checkNodeWeights(d.nodeWeights, nv, label, fail);
        const auto& x = mesh.positions();
        detail::ElasticTets et;
        et.model = d.model;
        std::vector<double> mass(nv, 0.0);
        const int32_t off = tetFirst[b];
        for (size_t t = 0; t < mesh.tetCount(); ++t) {
            const Tet& e = mesh.tets()[t];
            Mat3 dm;
            for (int k = 0; k < 3; ++k)
                dm.col(k) = x[e[k + 1]] - x[e[0]];
            const double vol = dm.determinant() / 6.0;
            if (!(vol > 0))
                fail(label, "tet " + std::to_string(t) + " has non-positive rest volume " + formatNumber(vol) + " m^3");
            et.tets.push_back({e[0] + off, e[1] + off, e[2] + off, e[3] + off});
            et.dmInv.push_back(dm.inverse());
            et.volume.push_back(vol);
            double w = 1.0;
            if (!d.nodeWeights.empty())
                w = 0.25 * (d.nodeWeights[e[0]] + d.nodeWeights[e[1]] + d.nodeWeights[e[2]] + d.nodeWeights[e[3]]);
            et.weight.push_back(w);
            for (int k = 0; k < 4; ++k)
                mass[e[k]] += d.density * vol / 4.0;
        }
        checkFixed(d.fixedNodes, nv, label, fail);
        std::vector<uint8_t> fixed(nv, 0);
        for (int32_t f : d.fixedNodes)
            fixed[f] = 1;
        if (d.strainLimits) {
            const TetStrainLimits& sl = *d.strainLimits;
            if (auto why = validateAxes(sl.axes); !why.empty()) fail(label, "strain limits: " + why);
            checkLimits(sl.limits, 3, sl.tets, mesh.tetCount(), "tet", label, fail);
            std::vector<Tet> tets;
            std::vector<Mat3> M;
            std::vector<double> vol;
            for (int32_t t : allOr(sl.tets, mesh.tetCount())) {
                const Tet& e = mesh.tets()[t];
                tets.push_back(et.tets[t]);
                M.push_back(tetMaterialDmInv({x[e[0]], x[e[1]], x[e[2]], x[e[3]]}, sl.axes));
                vol.push_back(et.volume[t]);
            }
            strainBlocks.push_back(detail::makeTetStrainBlock(std::move(tets), std::move(M), std::move(vol),
                                                              detail::expandStrainLimits(sl.limits)));
            strainBlockBody.push_back(b);
        }
        Range r;
        r.name = d.name;
        r.first = off;
        r.tetWeight = et.weight;
        for (const Tet& e : et.tets)
            r.elems.push_back({e[0], e[1], e[2], e[3]});
        r.active.assign(r.elems.size(), 1);
        r.reshaped.assign(r.elems.size(), 0);
        r.strainUnit.assign(r.elems.size(), -1);
        r.elasticBlock = static_cast<int>(eng.blocks.size());
        if (d.strainLimits) {
            int32_t unit = 0;
            for (int32_t t : allOr(d.strainLimits->tets, mesh.tetCount()))
                r.strainUnit[t] = unit++;
        }
        sys->m_tet.push_back(std::move(r));
        eng.addParticles(x, mass, fixed);
        bool simd = false;
        eng.blocks.push_back(detail::makeElasticBlock(std::move(et), settings.simd, &simd));
        sys->m_simd = sys->m_simd || simd;
    }
    for (size_t k = 0; k < strainBlocks.size(); ++k) {
        sys->m_tet[strainBlockBody[k]].strainBlock = static_cast<int>(eng.blocks.size());
        eng.blocks.push_back(std::move(strainBlocks[k]));
    }

    // ---- attachments (before the surfaces: snapping moves their rest vertices) ----
    std::vector<detail::Tie> ties;
    for (size_t a = 0; a < desc.attachments.size(); ++a) {
        const SurfaceAttachmentDesc& at = desc.attachments[a];
        const std::string label = "attachment " + std::to_string(a) + ": ";
        if (at.surface >= desc.surfaces.size())
            fail(label, "surface " + std::to_string(at.surface) + " does not exist");
        if (at.tetBody >= desc.tetBodies.size())
            fail(label, "tet body " + std::to_string(at.tetBody) + " does not exist");
        if (!std::isfinite(at.compliance) || at.compliance < 0) fail(label, "compliance must be finite and >= 0");
        if (!std::isfinite(at.maxDistance) || at.maxDistance < 0) fail(label, "max distance must be finite and >= 0");
        const TetMesh& cage = *desc.tetBodies[at.tetBody].mesh;
        const auto proj = projectOntoBoundary(cage, surfX[at.surface], at.maxDistance);
        if (proj.empty())
            fail(label, "no vertex of surface '" + desc.surfaces[at.surface].name + "' lies within " +
                            formatNumber(at.maxDistance) + " m of the boundary of '" + desc.tetBodies[at.tetBody].name +
                            "'");
        for (const BoundaryProjection& p : proj) {
            detail::Tie t;
            t.p = surfFirst[at.surface] + p.point;
            t.n = 3;
            for (int k = 0; k < 3; ++k) {
                t.t[k] = tetFirst[at.tetBody] + p.vertices[k];
                t.b[k] = p.bary[k];
            }
            t.compliance = at.compliance;
            ties.push_back(t);
            if (at.snap) {
                Vec3 q = Vec3::Zero();
                for (int k = 0; k < 3; ++k)
                    q += p.bary[k] * cage.positions()[p.vertices[k]];
                surfX[at.surface][p.point] = q;
            }
        }
    }

    // ---- surfaces ----
    for (size_t s = 0; s < desc.surfaces.size(); ++s) {
        const SurfaceBodyDesc& d = desc.surfaces[s];
        const std::string label = surfLabel(s);
        const TriMesh& mesh = *d.mesh;
        const size_t nv = mesh.vertexCount();
        const auto& x = surfX[s];
        if (!std::isfinite(d.arealDensity) || d.arealDensity <= 0)
            fail(label, "areal density must be positive and finite");
        if (!std::isfinite(d.stretchStiffness) || d.stretchStiffness < 0)
            fail(label, "stretch stiffness must be finite and >= 0");
        if (!d.uv.empty() && d.uv.size() != nv)
            fail(label, "uv: " + std::to_string(d.uv.size()) + " given for " + std::to_string(nv) + " vertices");
        for (size_t i = 0; i < d.uv.size(); ++i)
            if (!d.uv[i].allFinite()) fail(label, "uv " + std::to_string(i) + " is not finite");
        checkFixed(d.fixedNodes, nv, label, fail);
        checkNodeWeights(d.nodeWeights, nv, label, fail);
        const int32_t off = surfFirst[s];
        std::vector<double> mass(nv, 0.0), area(mesh.triangleCount()), stiffness(mesh.triangleCount());
        std::vector<Tri> tris;
        std::vector<Mat2> restInv;
        for (size_t t = 0; t < mesh.triangleCount(); ++t) {
            const Tri& e = mesh.triangles()[t];
            area[t] = 0.5 * (x[e[1]] - x[e[0]]).cross(x[e[2]] - x[e[0]]).norm();
            Mat2 M;
            if (!triangleRestDmInv({x[e[0]], x[e[1]], x[e[2]]}, M))
                fail(label,
                     "triangle " + std::to_string(t) + " is degenerate (area " + formatNumber(area[t]) + " m^2)");
            tris.push_back({e[0] + off, e[1] + off, e[2] + off});
            restInv.push_back(M);
            // painted fascia: a triangle's stiffness is k times the mean of its vertices' weights
            stiffness[t] =
                d.stretchStiffness *
                (d.nodeWeights.empty() ? 1.0 : (d.nodeWeights[e[0]] + d.nodeWeights[e[1]] + d.nodeWeights[e[2]]) / 3.0);
            for (int k = 0; k < 3; ++k)
                mass[e[k]] += d.arealDensity * area[t] / 3.0;
        }
        std::vector<uint8_t> fixed(nv, 0);
        for (int32_t f : d.fixedNodes)
            fixed[f] = 1;
        Range r;
        r.name = d.name;
        r.first = off;
        for (const Tri& e : tris)
            r.elems.push_back({e[0], e[1], e[2], -1});
        r.active.assign(r.elems.size(), 1);
        r.reshaped.assign(r.elems.size(), 0);
        r.strainUnit.assign(r.elems.size(), -1);
        if (d.stretchStiffness > 0) r.elasticBlock = static_cast<int>(eng.blocks.size());
        if (d.strainLimits) {
            r.strainBlock = static_cast<int>(eng.blocks.size()) + (d.stretchStiffness > 0 ? 1 : 0);
            int32_t unit = 0;
            for (int32_t t : allOr(d.strainLimits->triangles, mesh.triangleCount()))
                r.strainUnit[t] = unit++;
        }
        sys->m_surf.push_back(std::move(r));
        eng.addParticles(x, mass, fixed);
        if (d.stretchStiffness > 0)
            eng.blocks.push_back(detail::makeMembraneBlock(tris, restInv, area, stiffness, settings.simd));
        if (d.strainLimits) {
            const TriStrainLimits& sl = *d.strainLimits;
            if (d.uv.empty()) fail(label, "strain limits need per-vertex uv coordinates");
            checkLimits(sl.limits, 2, sl.triangles, mesh.triangleCount(), "triangle", label, fail);
            std::vector<Tri> lt;
            std::vector<Mat2> M;
            std::vector<double> la;
            for (int32_t t : allOr(sl.triangles, mesh.triangleCount())) {
                const Tri& e = mesh.triangles()[t];
                Mat2 m;
                if (!triangleUvDmInv({x[e[0]], x[e[1]], x[e[2]]}, {d.uv[e[0]], d.uv[e[1]], d.uv[e[2]]}, m))
                    fail(label, "triangle " + std::to_string(t) + " has a degenerate uv frame");
                lt.push_back(tris[t]);
                M.push_back(m);
                la.push_back(area[t]);
            }
            eng.blocks.push_back(detail::makeTriStrainBlock(std::move(lt), std::move(M), std::move(la),
                                                            detail::expandStrainLimits(sl.limits)));
        }
    }

    // ---- embeddings ----
    for (size_t k = 0; k < desc.embeddings.size(); ++k) {
        const EmbeddingDesc& em = desc.embeddings[k];
        const std::string label = "embedding " + std::to_string(k) + ": ";
        if (em.embedded >= desc.tetBodies.size() || em.cage >= desc.tetBodies.size())
            fail(label, "tet body " + std::to_string(std::max(em.embedded, em.cage)) + " does not exist");
        if (em.embedded == em.cage) fail(label, "a body cannot be embedded in itself");
        if (!std::isfinite(em.compliance) || em.compliance < 0) fail(label, "compliance must be finite and >= 0");
        std::vector<CageLocation> loc;
        try {
            loc = locateInCage(*desc.tetBodies[em.cage].mesh, desc.tetBodies[em.embedded].mesh->positions(),
                               em.tolerance);
        } catch (const OutsideCageError& e) {
            fail(label, "'" + desc.tetBodies[em.embedded].name + "' in '" + desc.tetBodies[em.cage].name + "': node " +
                            std::to_string(e.point) + " " + e.howFar);
        } catch (const std::invalid_argument& e) { // a bad tolerance: a programming error, named as is
            fail(label, e.what());
        }
        for (const CageLocation& c : loc) {
            detail::Tie t;
            t.p = tetFirst[em.embedded] + c.point;
            t.n = 4;
            const Tet& e = desc.tetBodies[em.cage].mesh->tets()[c.tet];
            for (int j = 0; j < 4; ++j) {
                t.t[j] = tetFirst[em.cage] + e[j];
                t.b[j] = c.bary[j];
            }
            t.compliance = em.compliance;
            ties.push_back(t);
        }
    }
    for (const detail::Tie& t : ties)
        sys->m_ties.push_back({t.p, t.t, t.b, t.n, t.compliance});
    if (!ties.empty()) eng.blocks.push_back(detail::makeCouplingBlock(std::move(ties)));

    bool anyFree = false;
    for (size_t i = 0; i < eng.particleCount() && !anyFree; ++i)
        anyFree = detail::particleInvMass(eng.xw.data(), i) > 0;
    if (!anyFree) fail("", singleBody ? "body has no free node" : "the system has no free particle");

    if (settings.primalCorrection && !eng.supportsPrimalCorrection())
        fail("", "primal_correction is available for elastic tets only (no strain limits, "
                 "membranes or couplings)");
    eng.colour();
    if (eng.usefulThreads(settings.threads) > 1) sys->m_pool = std::make_unique<detail::WorkerPool>(settings.threads);
    sys->m_rest.reserve(eng.particleCount());
    for (size_t i = 0; i < eng.particleCount(); ++i)
        sys->m_rest.push_back(detail::particlePosition(eng.xw.data(), i));
    sys->refreshMirrors();
    return sys;
}

void XpbdSystem::refreshMirrors() {
    const double* xw = m_engine->xw.data();
    auto fill = [&](Range& r, size_t nv) {
        r.x.resize(nv);
        r.v.resize(nv);
        for (size_t i = 0; i < nv; ++i) {
            r.x[i] = detail::particlePosition(xw, r.first + static_cast<int32_t>(i));
            r.v[i] = m_engine->v[r.first + i];
        }
    };
    const size_t total = m_engine->particleCount();
    std::vector<Range*> all;
    for (Range& r : m_tet)
        all.push_back(&r);
    for (Range& r : m_surf)
        all.push_back(&r);
    for (size_t k = 0; k < all.size(); ++k) {
        const size_t end = k + 1 < all.size() ? static_cast<size_t>(all[k + 1]->first) : total;
        fill(*all[k], end - all[k]->first);
    }
}

void XpbdSystem::setIterationHook(XpbdIterationHook hook) {
    m_engine->iterationHook = std::move(hook);
    m_engine->iterationHookActive = true;
    m_engine->hookFirst = 0;
    m_engine->hookEnd = SIZE_MAX;
}

void XpbdSystem::setIterationHookParticles(size_t first, size_t count) {
    m_engine->hookFirst = first;
    m_engine->hookEnd = first + count;
}

void XpbdSystem::setIterationHookActive(bool active) {
    m_engine->iterationHookActive = active;
}

StepStats XpbdSystem::step() {
    const StepStats st = m_engine->frame(m_settings, m_pool.get());
    refreshMirrors();
    return st;
}

void XpbdSystem::setState(Range& r, const std::vector<Vec3>& x, const std::vector<Vec3>& v, const char* what) {
    const std::string where = std::string("sim::XpbdSystem::") + what + "(): ";
    if (x.size() != r.x.size() || v.size() != r.x.size())
        throw PreconditionError(where, "expected " + std::to_string(r.x.size()) + " positions and velocities, got " +
                                           std::to_string(x.size()) + " and " + std::to_string(v.size()));
    for (size_t i = 0; i < x.size(); ++i)
        if (!x[i].allFinite() || !v[i].allFinite())
            throw PreconditionError(where, "node " + std::to_string(i) + " is not finite");
    double* xw = m_engine->xw.data();
    for (size_t i = 0; i < x.size(); ++i) {
        double* p = xw + 4 * (r.first + i);
        p[0] = x[i].x();
        p[1] = x[i].y();
        p[2] = x[i].z();
        m_engine->v[r.first + i] = p[3] == 0 ? Vec3::Zero() : v[i];
    }
    refreshMirrors();
}

void XpbdSystem::setAddedInertia(size_t b, const std::vector<double>& extra) {
    const Range& r = m_tet.at(b);
    const std::string where = "sim::XpbdSystem::setAddedInertia(): ";
    if (extra.size() != r.x.size())
        throw PreconditionError(where, "expected " + std::to_string(r.x.size()) + " values, got " +
                                           std::to_string(extra.size()));
    for (size_t i = 0; i < extra.size(); ++i)
        if (!std::isfinite(extra[i]) || extra[i] < 0)
            throw PreconditionError(where, "node " + std::to_string(i) + ": extra inertia must be finite and >= 0");
    detail::Engine& eng = *m_engine;
    if (m_added.empty()) m_added.assign(eng.particleCount(), 0.0);
    if (eng.gravityScale.empty()) eng.gravityScale.assign(eng.particleCount(), 1.0);
    for (size_t i = 0; i < extra.size(); ++i) {
        const size_t p = r.first + i;
        double& w = eng.xw[4 * p + 3];
        m_added[p] = extra[i]; // a fixed node records it (its inertia is infinite anyway) but stays
        if (w == 0) continue;
        w = 1.0 / (eng.mass[p] + extra[i]);
        eng.gravityScale[p] = eng.mass[p] / (eng.mass[p] + extra[i]);
    }
}

std::vector<double> XpbdSystem::addedInertia(size_t b) const {
    const Range& r = m_tet.at(b);
    if (m_added.empty()) return std::vector<double>(r.x.size(), 0.0);
    return {m_added.begin() + r.first, m_added.begin() + r.first + static_cast<long>(r.x.size())};
}

void XpbdSystem::setTetState(size_t b, const std::vector<Vec3>& x, const std::vector<Vec3>& v) {
    setState(m_tet.at(b), x, v, "setTetState");
}

void XpbdSystem::setSurfaceState(size_t s, const std::vector<Vec3>& x, const std::vector<Vec3>& v) {
    setState(m_surf.at(s), x, v, "setSurfaceState");
}

// ---- dissection ------------------------------------------------------------------------------

void XpbdSystem::syncStrainUnit(Range& r, size_t t) {
    if (r.strainBlock < 0 || r.strainUnit[t] < 0) return;
    m_engine->blocks[r.strainBlock]->setUnitActive(static_cast<size_t>(r.strainUnit[t]), r.active[t] && !r.reshaped[t]);
}

void XpbdSystem::setTetActive(size_t b, size_t t, bool active) {
    Range& r = m_tet.at(b);
    r.active.at(t) = active ? 1 : 0;
    m_engine->blocks[r.elasticBlock]->setUnitActive(t, active);
    syncStrainUnit(r, t);
}

void XpbdSystem::holdTetNode(size_t b, size_t v) {
    const Range& r = m_tet.at(b);
    if (v >= r.x.size()) throw std::out_of_range("sim::XpbdSystem::holdTetNode(): node out of range");
    detail::Engine& eng = *m_engine;
    const size_t p = r.first + v;
    eng.xw[4 * p + 3] = 0;
    eng.v[p] = Vec3::Zero();
}

bool XpbdSystem::tetActive(size_t b, size_t t) const {
    return m_tet.at(b).active.at(t) != 0;
}

void XpbdSystem::setTetRestShape(size_t b, size_t t, const Mat3& Fs) {
    Range& r = m_tet.at(b);
    const auto& e = r.elems.at(t);
    const std::string where = "sim::XpbdSystem::setTetRestShape(): tet body " + std::to_string(b) + " ('" + r.name +
                              "'), tet " + std::to_string(t) + ": ";
    if (!Fs.allFinite()) throw std::invalid_argument(where + "Fs is not finite");
    const double det = Fs.determinant();
    if (!(det > 1e-12)) throw std::invalid_argument(where + "det Fs = " + formatNumber(det) + " (must be > 1e-12)");
    Mat3 dm;
    for (int k = 0; k < 3; ++k)
        dm.col(k) = m_rest[e[k + 1]] - m_rest[e[0]];
    const Mat3 inv = (Fs * dm).inverse();
    if (!inv.allFinite()) throw std::invalid_argument(where + "the shrunk rest tet is singular");
    double m[9];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            m[3 * i + j] = inv(i, j);
    m_engine->blocks[r.elasticBlock]->setUnitRestInverse(t, m);
    r.reshaped[t] = Fs.isIdentity(0) ? 0 : 1;
    syncStrainUnit(r, t);
}

void XpbdSystem::setTriangleActive(size_t s, size_t t, bool active) {
    Range& r = m_surf.at(s);
    r.active.at(t) = active ? 1 : 0;
    if (r.elasticBlock >= 0) m_engine->blocks[r.elasticBlock]->setUnitActive(t, active);
    syncStrainUnit(r, t);
}

bool XpbdSystem::triangleActive(size_t s, size_t t) const {
    return m_surf.at(s).active.at(t) != 0;
}

void XpbdSystem::setTriangleRestShape(size_t s, size_t t, const Mat3& Fs) {
    Range& r = m_surf.at(s);
    const auto& e = r.elems.at(t);
    const std::string where = "sim::XpbdSystem::setTriangleRestShape(): surface " + std::to_string(s) + " ('" + r.name +
                              "'), triangle " + std::to_string(t) + ": ";
    if (!Fs.allFinite()) throw std::invalid_argument(where + "Fs is not finite");
    const Vec3 x0 = m_rest[e[0]];
    Mat2 M;
    if (!triangleRestDmInv({x0, x0 + Fs * (m_rest[e[1]] - x0), x0 + Fs * (m_rest[e[2]] - x0)}, M))
        throw std::invalid_argument(where + "the shrunk rest triangle is degenerate");
    const double m[4] = {M(0, 0), M(0, 1), M(1, 0), M(1, 1)};
    if (r.elasticBlock >= 0) m_engine->blocks[r.elasticBlock]->setUnitRestInverse(t, m);
    r.reshaped[t] = Fs.isIdentity(0) ? 0 : 1;
    syncStrainUnit(r, t);
}

double XpbdSystem::maxTieGap() const {
    const double* xw = m_engine->xw.data();
    double gap = 0;
    for (const TieRecord& t : m_ties) {
        Vec3 c = detail::particlePosition(xw, t.p);
        for (int k = 0; k < t.n; ++k)
            c -= t.b[k] * detail::particlePosition(xw, t.t[k]);
        gap = std::max(gap, c.norm());
    }
    return gap;
}

std::vector<double> XpbdSystem::tiedInertia(size_t b) const {
    const Range& r = m_tet.at(b);
    auto inertiaOf = [&](int32_t i) { return m_engine->mass[i] + (m_added.empty() ? 0.0 : m_added[i]); };
    std::vector<double> added(r.x.size(), 0.0);
    const double* xw = m_engine->xw.data();
    std::vector<double> share(m_engine->particleCount(), 0.0); // B_k
    for (const TieRecord& t : m_ties)
        if (t.compliance == 0)
            for (int k = 0; k < t.n; ++k)
                share[t.t[k]] += std::max(t.b[k], 0.0);
    for (const TieRecord& t : m_ties) {
        if (t.compliance != 0 || t.p < r.first || t.p >= r.first + static_cast<int32_t>(added.size())) continue;
        double inv = 0; // Σ b_k B_k / m_k; fixed nodes (inverse mass 0) add nothing
        for (int k = 0; k < t.n; ++k)
            if (detail::particleInvMass(xw, t.t[k]) > 0 && t.b[k] > 0)
                inv += t.b[k] * share[t.t[k]] / inertiaOf(t.t[k]);
        added[t.p - r.first] += inv > 0 ? 1.0 / inv : std::numeric_limits<double>::infinity();
    }
    return added;
}

double XpbdSystem::elasticEnergy() const {
    return m_engine->energy(m_settings.threads, m_pool.get());
}

double XpbdSystem::kineticEnergy() const {
    double e = 0;
    for (size_t i = 0; i < m_engine->particleCount(); ++i)
        e += 0.5 * (m_engine->mass[i] + (m_added.empty() ? 0.0 : m_added[i])) * m_engine->v[i].squaredNorm();
    return e;
}

double XpbdSystem::potentialEnergy() const {
    double e = 0;
    const double* xw = m_engine->xw.data();
    for (size_t i = 0; i < m_engine->particleCount(); ++i)
        e -= m_engine->mass[i] * m_settings.gravity.dot(detail::particlePosition(xw, i) - m_rest[i]);
    return e;
}

double XpbdSystem::totalMass() const {
    double m = 0;
    for (double x : m_engine->mass)
        m += x;
    return m;
}

int XpbdSystem::colourCount() const {
    return m_engine->colourCount();
}

} // namespace viscera::sim
