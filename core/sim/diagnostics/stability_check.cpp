#include "sim/diagnostics/stability_check.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace viscera::sim {

namespace {

/// Largest tangent stiffness of the model over the strains tissue reaches in practice (±25%
/// uniaxial and volumetric): d P_11 / d F_11 by central differences. Catches curve-edited
/// materials whose toe stiffens far above the rest stiffness.
double probedStiffness(const TetConstraintModel& model) {
    double k = model.restStiffness();
    const double d = 1e-6;
    for (double l : {0.8, 0.9, 1.1, 1.2, 1.25}) {
        for (int mode = 0; mode < 2; ++mode) {
            // mode 0: uniaxial diag(a, 1, 1); mode 1: near-volumetric diag(a, l, l).
            auto F = [&](double a) {
                Mat3 m = Mat3::Identity();
                m(0, 0) = a;
                if (mode == 1) m(1, 1) = m(2, 2) = l;
                return m;
            };
            const double kk =
                (model.energyDensityGradient(F(l + d))(0, 0) - model.energyDensityGradient(F(l - d))(0, 0)) / (2 * d);
            if (std::isfinite(kk)) k = std::max(k, kk);
        }
    }
    return k;
}

} // namespace

StabilityFigures assessStability(const TetMesh& mesh, const TetConstraintModel& model, double density,
                                 const std::vector<double>& nodeWeights, const XpbdSettings& settings) {
    return assessStability(mesh, model, density, nodeWeights, settings, {});
}

StabilityFigures assessStability(const TetMesh& mesh, const TetConstraintModel& model, double density,
                                 const std::vector<double>& nodeWeights, const XpbdSettings& settings,
                                 const std::vector<double>& tiedMass) {
    StabilityFigures f;
    const double h = settings.dt / settings.substeps;
    const double k = probedStiffness(model);
    // Lumped own masses (without the density, which cancels) for the tied-inertia ratio.
    if (!tiedMass.empty() && tiedMass.size() != mesh.vertexCount())
        throw std::invalid_argument("sim::assessStability(): tiedMass has " + std::to_string(tiedMass.size()) +
                                    " values for " + std::to_string(mesh.vertexCount()) + " nodes");
    std::vector<double> own;
    if (!tiedMass.empty()) {
        own.assign(mesh.vertexCount(), 0.0);
        for (int32_t t = 0; t < static_cast<int32_t>(mesh.tetCount()); ++t)
            for (int32_t v : mesh.tets()[t])
                own[v] += std::abs(mesh.signedVolume(t)) / 4.0;
    }
    for (int32_t t = 0; t < static_cast<int32_t>(mesh.tetCount()); ++t) {
        const double vol = std::abs(mesh.signedVolume(t));
        if (!(vol > 0)) continue;
        double w = 1.0;
        if (!nodeWeights.empty()) {
            w = 0;
            for (int32_t v : mesh.tets()[t])
                w += nodeWeights[v] / 4.0;
        }
        const double L = std::cbrt(6.0 * vol);
        double inertia = 1.0; // smallest (m_i + tied_i) / m_i over the tet's nodes
        if (!tiedMass.empty()) {
            inertia = std::numeric_limits<double>::infinity();
            for (int32_t v : mesh.tets()[t])
                inertia = std::min(inertia, 1.0 + tiedMass[v] / (density * own[v]));
        }
        const double s = k * w * h * h / (density * L * L) / inertia;
        if (s > f.maxStiffnessNumber) {
            f.maxStiffnessNumber = s;
            f.worstTet = t;
        }
    }
    // s scales with h², so the substep count that brings it under the limit scales with sqrt(s).
    // Extra iterations per substep are not credited: the suite measured the limit at one sweep.
    // The smallest count with s ≤ limit, also when the current one has room to spare (the studio
    // shows it live); at least 1.
    f.requiredSubsteps = std::max(
        1, static_cast<int>(std::ceil(settings.substeps * std::sqrt(f.maxStiffnessNumber / kMaxStiffnessNumber))));
    return f;
}

std::string stabilityProblem(const std::string& body, const StabilityFigures& f, const XpbdSettings& settings) {
    if (f.ok()) return {};
    char buf[320];
    std::snprintf(buf, sizeof buf,
                  "body '%s': stiffness number %.3g at tet %d exceeds %.3g (substep %.3g ms); use at least %d "
                  "substeps per frame or a softer material",
                  body.c_str(), f.maxStiffnessNumber, f.worstTet, kMaxStiffnessNumber,
                  1e3 * settings.dt / settings.substeps, f.requiredSubsteps);
    return buf;
}

} // namespace viscera::sim
