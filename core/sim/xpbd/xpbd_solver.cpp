#include "sim/xpbd/xpbd_solver.hpp"

#include "sim/material/stable_neo_hookean.hpp"
#include "sim/util/error.hpp"
#include "sim/xpbd/detail/blocks.hpp"
#include "sim/xpbd/detail/engine.hpp"

#include <Eigen/Dense>

#include <chrono>
#include <cmath>
#include <stdexcept>

namespace viscera::sim {

XpbdSolver::XpbdSolver() = default;
XpbdSolver::~XpbdSolver() = default;

std::unique_ptr<XpbdSolver> XpbdSolver::create(const TetBodyDesc& body, const XpbdSettings& settings) {
    const std::string where = "sim::XpbdSolver::create(): ";
    XpbdSystemDesc desc;
    desc.tetBodies.push_back(body);
    std::unique_ptr<XpbdSolver> s(new XpbdSolver());
    s->m_sys = XpbdSystem::build(desc, settings, where, true);
    // The problem template (validated by build above).
    const TetMesh& mesh = *body.mesh;
    const auto& x = mesh.positions();
    StepProblem& p = s->m_template;
    p.model = body.model;
    p.tets = mesh.tets();
    p.weight = s->m_sys->tetWeights(0);
    for (const Tet& e : p.tets) {
        Mat3 dm;
        for (int k = 0; k < 3; ++k)
            dm.col(k) = x[e[k + 1]] - x[e[0]];
        p.dmInv.push_back(dm.inverse());
        p.volume.push_back(dm.determinant() / 6.0);
    }
    const detail::Engine& eng = *s->m_sys->m_engine;
    p.mass = eng.mass;
    p.fixed.resize(eng.particleCount());
    for (size_t i = 0; i < p.fixed.size(); ++i)
        p.fixed[i] = detail::particleInvMass(eng.xw.data(), i) == 0 ? 1 : 0;
    return s;
}

std::unique_ptr<XpbdSolver> XpbdSolver::create(const TetMesh& rest, const Material& material,
                                               const std::vector<int32_t>& fixedNodes, const XpbdSettings& settings) {
    if (auto why = validate(material); !why.empty()) throw PreconditionError("sim::XpbdSolver::create(): ", why);
    TetBodyDesc body;
    body.mesh = &rest;
    body.model = std::make_shared<StableNeoHookeanModel>(material.mu(), material.lambda());
    body.density = material.density;
    body.fixedNodes = fixedNodes;
    return create(body, settings);
}

StepStats XpbdSolver::step() {
    return m_sys->step();
}
void XpbdSolver::setIterationHook(XpbdIterationHook hook) {
    m_sys->setIterationHook(std::move(hook));
}
const std::vector<Vec3>& XpbdSolver::positions() const {
    return m_sys->tetPositions(0);
}
const std::vector<Vec3>& XpbdSolver::velocities() const {
    return m_sys->tetVelocities(0);
}
const XpbdSettings& XpbdSolver::settings() const {
    return m_sys->settings();
}
int XpbdSolver::colourCount() const {
    return m_sys->colourCount();
}
bool XpbdSolver::usesSimd() const {
    return m_sys->usesSimd();
}
double XpbdSolver::elasticEnergy() const {
    return m_sys->elasticEnergy();
}
double XpbdSolver::kineticEnergy() const {
    return m_sys->kineticEnergy();
}
double XpbdSolver::potentialEnergy() const {
    return m_sys->potentialEnergy();
}
double XpbdSolver::totalMass() const {
    return m_sys->totalMass();
}

void XpbdSolver::setState(const std::vector<Vec3>& x, const std::vector<Vec3>& v) {
    try {
        m_sys->setTetState(0, x, v);
    } catch (const PreconditionError& e) {
        throw PreconditionError("sim::XpbdSolver::setState(): ", e.rule);
    }
}

StepProblem XpbdSolver::nextSubstepProblem() const {
    StepProblem p = m_template;
    const XpbdSettings& s = m_sys->settings();
    p.h = s.dt / s.substeps;
    const Vec3 hg = p.h * s.gravity;
    const auto& x = positions();
    const auto& v = velocities();
    p.xTilde.resize(x.size());
    for (size_t i = 0; i < x.size(); ++i) {
        p.xTilde[i] = x[i];
        if (p.fixed[i]) continue;
        const Vec3 vi = v[i] + hg;
        p.xTilde[i].x() += p.h * vi.x();
        p.xTilde[i].y() += p.h * vi.y();
        p.xTilde[i].z() += p.h * vi.z();
    }
    return p;
}

namespace {

/// XpbdIteration::Chebyshev after sweep k on the packed positions xw (x, y, z, w per particle):
/// extrapolates from x_{k-2} (before2) and shifts the history. Returns its wall time, s.
double chebyshevStep(detail::ParticleArray& xw, detail::ParticleArray& before2, detail::ParticleArray& before1, int k,
                     double rho, double& omega) {
    const auto t0 = std::chrono::steady_clock::now();
    if (k >= 2) {
        omega = k == 2 ? 2.0 / (2.0 - rho * rho) : 4.0 / (4.0 - rho * rho * omega);
        for (size_t i = 0; i + 3 < xw.size(); i += 4) {
            if (xw[i + 3] == 0) continue; // fixed
            for (size_t r = 0; r < 3; ++r)
                xw[i + r] = omega * (xw[i + r] - before2[i + r]) + before2[i + r];
        }
    }
    before2.swap(before1);
    before1 = xw;
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

} // namespace

void XpbdSolver::iterateOn(const StepProblem& p, int iterations, const IterateObserver& observe, XpbdIteration mode,
                           double chebyshevRho) const {
    const std::string where = "sim::XpbdSolver::iterateOn(): ";
    if (iterations < 1) throw std::invalid_argument(where + "iterations must be >= 1");
    if (!(p.h > 0) || !std::isfinite(p.h)) throw std::invalid_argument(where + "h must be positive and finite");
    const size_t nv = p.xTilde.size(), nt = p.tets.size();
    if (p.mass.size() != nv || p.fixed.size() != nv)
        throw std::invalid_argument(where + "xTilde, mass and fixed must have one entry per node");
    if (p.dmInv.size() != nt || p.volume.size() != nt || p.weight.size() != nt)
        throw std::invalid_argument(where + "dmInv, volume and weight must have one entry per tet");
    if (!p.model) throw std::invalid_argument(where + "model is null");
    if (mode == XpbdIteration::Chebyshev && !(chebyshevRho >= 0 && chebyshevRho < 1))
        throw std::invalid_argument(where + "chebyshev rho must be in [0, 1)");
    if (p.model->count() < 1 || p.model->count() > kMaxTetConstraints)
        throw std::invalid_argument(where + "model must have 1 or 2 constraints per tet");
    for (size_t t = 0; t < nt; ++t) {
        for (int32_t v : p.tets[t])
            if (v < 0 || static_cast<size_t>(v) >= nv)
                throw std::invalid_argument(where + "tet " + std::to_string(t) + " references node " +
                                            std::to_string(v) + " (problem has " + std::to_string(nv) + " nodes)");
        if (!(p.volume[t] > 0) || !(p.weight[t] > 0))
            throw std::invalid_argument(where + "tet " + std::to_string(t) + " needs a positive volume and weight");
    }
    detail::Engine eng;
    eng.addParticles(p.xTilde, p.mass, p.fixed);
    eng.blocks.push_back(detail::makeElasticBlock({p.tets, p.dmInv, p.volume, p.weight, p.model}, settings().simd));
    eng.colour();
    const double h2inv = 1.0 / (p.h * p.h);
    double seconds = 0;
    std::vector<Vec3> xk(nv);
    detail::ParticleArray before2, before1 = eng.xw; // Chebyshev: x_{k-2}, x_{k-1}
    double omega = 1;
    for (int k = 1; k <= iterations; ++k) {
        seconds += eng.sweep(k == 1, h2inv, settings().threads, m_sys->m_pool.get());
        if (mode == XpbdIteration::PrimalCorrected)
            seconds += eng.primalCorrection(p.xTilde, settings().threads, m_sys->m_pool.get());
        if (mode == XpbdIteration::Chebyshev)
            seconds += chebyshevStep(eng.xw, before2, before1, k, chebyshevRho, omega);
        for (size_t i = 0; i < nv; ++i)
            xk[i] = detail::particlePosition(eng.xw.data(), static_cast<int32_t>(i));
        if (observe) observe(k, xk, seconds);
    }
}

} // namespace viscera::sim
