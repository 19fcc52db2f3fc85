#include "sim/scene/world.hpp"

#include "sim/util/error.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace viscera::sim {
namespace {
const char* kXpbd = "xpbd";
const char* kGravity = "gravity";

bool has(const std::vector<std::string>& v, const std::string& x) {
    return std::find(v.begin(), v.end(), x) != v.end();
}
} // namespace

const std::vector<std::string>& supportedFeatures() {
    static const std::vector<std::string> f = {kGravity, kXpbd};
    return f;
}

std::unique_ptr<World> World::assemble(const SceneDesc& scene, std::vector<std::unique_ptr<TetMesh>> meshes,
                                       const std::vector<std::string>& features, const std::string& origin) {
    for (const std::string& f : features)
        if (!has(supportedFeatures(), f)) {
            std::string list;
            for (const auto& s : supportedFeatures()) list += (list.empty() ? "" : ", ") + s;
            throw InputError(origin + ": features: '" + f + "' is not supported by this player (supported: " +
                             list + ")");
        }
    if (meshes.size() != scene.bodies.size())
        throw std::invalid_argument("sim::World::assemble(): one mesh per body is required");
    if (!scene.bodies.empty() && !has(features, scene.solverType))
        throw InputError(origin + ": features: the scene uses solver '" + scene.solverType +
                         "' but the manifest does not declare it");
    XpbdSettings settings = scene.xpbd;
    if (settings.gravity.squaredNorm() > 0 && !has(features, kGravity))
        throw InputError(origin + ": features: the scene sets gravity but the manifest does not declare 'gravity'");
    if (!has(features, kGravity)) settings.gravity.setZero();

    std::unique_ptr<World> w(new World());
    w->m_dt = settings.dt;
    for (size_t i = 0; i < scene.bodies.size(); ++i) {
        const BodyDesc& b = scene.bodies[i];
        try {
            w->m_bodies.push_back(XpbdSolver::create(*meshes[i], b.material, b.fixedNodes, settings));
        } catch (const std::invalid_argument& e) {
            std::string why = e.what();
            const std::string prefix = "sim::XpbdSolver::create(): ";
            if (why.rfind(prefix, 0) == 0) why = why.substr(prefix.size());
            throw InputError(origin + ": body '" + b.name + "': cannot be simulated stably: " + why);
        }
        w->m_names.push_back(b.name);
    }
    w->m_meshes = std::move(meshes);
    if (!w->m_bodies.empty()) w->m_active.push_back(kXpbd);
    if (settings.gravity.squaredNorm() > 0) w->m_active.push_back(kGravity);
    std::sort(w->m_active.begin(), w->m_active.end());
    return w;
}

double World::totalEnergy() const {
    double e = 0;
    for (const auto& b : m_bodies) e += b->elasticEnergy() + b->kineticEnergy() + b->potentialEnergy();
    return e;
}

FrameRecord World::step() {
    FrameRecord rec;
    rec.index = m_frame;
    const auto t0 = std::chrono::steady_clock::now();
    for (auto& b : m_bodies) {
        StepStats st = b->step();
        rec.substeps = std::max(rec.substeps, st.substeps);
        rec.iterations = std::max(rec.iterations, st.iterations);
        rec.maxDisplacement = std::max(rec.maxDisplacement, st.maxDisplacement);
        rec.finite = rec.finite && st.finite;
        m_invariants.speedClamps += st.speedClamps;
    }
    rec.stepMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    rec.energy = totalEnergy();
    m_invariants.record(rec.finite && std::isfinite(rec.energy), rec.energy, rec.maxDisplacement, 0.0);
    ++m_frame;
    m_time += m_dt;
    return rec;
}

} // namespace viscera::sim
