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

namespace {

/// Per tet of the body: the stiffness number without tie inertia (k w h² / (ρ L²); 0 for a
/// degenerate tet) and the present ratio r = min over its nodes of (m_i + tied_i) / m_i; and the
/// nodes' own lumped masses.
struct TetNumbers {
    std::vector<double> raw, ratio, own;
};

TetNumbers tetNumbers(const TetMesh& mesh, const TetConstraintModel& model, double density,
                      const std::vector<double>& nodeWeights, const XpbdSettings& settings,
                      const std::vector<double>& tiedMass, const char* where) {
    const double h = settings.dt / settings.substeps;
    const double k = probedStiffness(model);
    if (!tiedMass.empty() && tiedMass.size() != mesh.vertexCount())
        throw std::invalid_argument(std::string(where) + "tiedMass has " + std::to_string(tiedMass.size()) +
                                    " values for " + std::to_string(mesh.vertexCount()) + " nodes");
    TetNumbers n;
    n.own.assign(mesh.vertexCount(), 0.0); // kg
    for (int32_t t = 0; t < static_cast<int32_t>(mesh.tetCount()); ++t)
        for (int32_t v : mesh.tets()[t])
            n.own[v] += density * std::abs(mesh.signedVolume(t)) / 4.0;
    n.raw.assign(mesh.tetCount(), 0.0);
    n.ratio.assign(mesh.tetCount(), 1.0);
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
        n.raw[t] = k * w * h * h / (density * L * L);
        if (!tiedMass.empty()) {
            double r = std::numeric_limits<double>::infinity();
            for (int32_t v : mesh.tets()[t])
                r = std::min(r, 1.0 + tiedMass[v] / n.own[v]);
            n.ratio[t] = r;
        }
    }
    return n;
}

} // namespace

StabilityFigures assessStability(const TetMesh& mesh, const TetConstraintModel& model, double density,
                                 const std::vector<double>& nodeWeights, const XpbdSettings& settings,
                                 const std::vector<double>& tiedMass) {
    StabilityFigures f;
    const TetNumbers n = tetNumbers(mesh, model, density, nodeWeights, settings, tiedMass, "sim::assessStability(): ");
    for (size_t t = 0; t < n.raw.size(); ++t) {
        const double s = n.raw[t] / n.ratio[t];
        if (s > f.maxStiffnessNumber) {
            f.maxStiffnessNumber = s;
            f.worstTet = static_cast<int>(t);
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

std::vector<double> stabilizingInertia(const TetMesh& mesh, const TetConstraintModel& model, double density,
                                       const std::vector<double>& nodeWeights, const XpbdSettings& settings,
                                       const std::vector<double>& tiedMass, double maxScale) {
    const TetNumbers n =
        tetNumbers(mesh, model, density, nodeWeights, settings, tiedMass, "sim::stabilizingInertia(): ");
    std::vector<double> extra(mesh.vertexCount(), 0.0);
    // A hair above the limit's ratio, so that the rounding of s = raw / ratio lands below it.
    constexpr double kMargin = 1 + 1e-9;
    for (size_t t = 0; t < n.raw.size(); ++t) {
        if (!(n.raw[t] / n.ratio[t] > kMaxStiffnessNumber)) continue;
        const double need = kMargin * n.raw[t] / kMaxStiffnessNumber; // ratio every node must reach
        for (int32_t v : mesh.tets()[t]) {
            const double tied = tiedMass.empty() ? 0.0 : tiedMass[v];
            if (!std::isfinite(tied)) continue;
            extra[v] = std::max(extra[v], (need - 1) * n.own[v] - tied);
        }
    }
    for (size_t v = 0; v < extra.size(); ++v)
        extra[v] = std::clamp(extra[v], 0.0, std::max(0.0, maxScale - 1) * n.own[v]);
    return extra;
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
