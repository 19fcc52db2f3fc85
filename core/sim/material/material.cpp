#include "sim/material/material.hpp"

#include "sim/material/curve.hpp"
#include "sim/material/energy_constraint.hpp"
#include "sim/material/laws.hpp"
#include "sim/material/stable_neo_hookean.hpp"
#include "sim/material/valanis_landel.hpp"
#include "sim/util/error.hpp"

#include <cmath>
#include <stdexcept>

namespace viscera::sim {
namespace {

struct ModelName {
    MaterialModel model;
    const char* name;
};
constexpr ModelName kNames[] = {
    {MaterialModel::StableNeoHookean, "stable_neo_hookean"},
    {MaterialModel::NeoHookean, "neo_hookean"},
    {MaterialModel::Linear, "linear"},
    {MaterialModel::StVenantKirchhoff, "st_venant_kirchhoff"},
    {MaterialModel::Corotated, "corotated"},
    {MaterialModel::ValanisLandel, "valanis_landel"},
};

std::optional<MonotoneCurve> curveFrom(const std::optional<CurveDesc>& d, const char* name, const std::string& ctx) {
    if (!d) return std::nullopt;
    std::vector<CurvePoint> pts;
    pts.reserve(d->points.size());
    for (const auto& p : d->points)
        pts.push_back({p[0], p[1]});
    return MonotoneCurve(name, std::move(pts),
                         d->unconstrained ? CurveShape::Unconstrained : CurveShape::StrictlyIncreasing, ctx);
}

} // namespace

std::string validate(const Material& m) {
    if (!std::isfinite(m.youngsModulus) || m.youngsModulus <= 0 || m.youngsModulus > MaterialLimits::maxYoungsModulus)
        return "youngs_modulus " + std::to_string(m.youngsModulus) + " must be in (0, 1e12] Pa";
    if (!std::isfinite(m.poissonRatio) || m.poissonRatio < 0 || m.poissonRatio >= MaterialLimits::maxPoissonRatio)
        return "poisson_ratio " + std::to_string(m.poissonRatio) + " must be in [0, 0.5)";
    if (!std::isfinite(m.density) || m.density <= 0 || m.density > MaterialLimits::maxDensity)
        return "density " + std::to_string(m.density) + " must be in (0, 1e5] kg/m^3";
    if (m.model != MaterialModel::ValanisLandel && (m.fPrime || m.gPrime || m.hPrime || !m.curvePreset.empty()))
        return "curves are only allowed with model valanis_landel";
    if (m.model == MaterialModel::ValanisLandel && m.curvePreset.empty() && !m.fPrime && !m.gPrime && !m.hPrime)
        return "model valanis_landel needs curves (a preset or f_prime/g_prime/h_prime)";
    if (!m.curvePreset.empty() && (m.fPrime || m.gPrime || m.hPrime))
        return "give either a curve preset or explicit curves, not both";
    return {};
}

MaterialModel materialModelFromName(const std::string& name) {
    for (const auto& n : kNames)
        if (name == n.name) return n.model;
    std::string list;
    for (const auto& n : kNames)
        list += (list.empty() ? "" : ", ") + std::string(n.name);
    throw std::invalid_argument("unknown material model '" + name + "' (supported: " + list + ")");
}

std::string materialModelName(MaterialModel model) {
    for (const auto& n : kNames)
        if (n.model == model) return n.name;
    return "unknown";
}

const std::vector<std::string>& materialModelNames() {
    static const std::vector<std::string> names = [] {
        std::vector<std::string> v;
        for (const auto& n : kNames)
            v.push_back(n.name);
        return v;
    }();
    return names;
}

ValanisLandelCurves materialCurves(const Material& m, const std::string& materialName) {
    const std::string ctx = "material '" + materialName + "'";
    if (m.model != MaterialModel::ValanisLandel)
        throw InputError(ctx + ": model " + materialModelName(m.model) + " has no curves");
    ValanisLandelCurves curves;
    if (!m.curvePreset.empty()) {
        try {
            curves = valanisLandelCurves(m.curvePreset, m.mu(), m.lambda());
        } catch (const std::exception& e) {
            throw InputError(ctx + ": curve preset '" + m.curvePreset + "': " + e.what());
        }
    } else {
        curves.fPrime = curveFrom(m.fPrime, "f'", ctx);
        curves.gPrime = curveFrom(m.gPrime, "g'", ctx);
        curves.hPrime = curveFrom(m.hPrime, "h'", ctx);
    }
    return curves;
}

void setMaterialCurves(Material& m, const ValanisLandelCurves& c) {
    auto desc = [](const std::optional<MonotoneCurve>& curve) -> std::optional<CurveDesc> {
        if (!curve) return std::nullopt;
        CurveDesc d;
        for (const CurvePoint& q : curve->controlPoints())
            d.points.push_back({q.x, q.y});
        d.unconstrained = curve->shape() == CurveShape::Unconstrained;
        return d;
    };
    m.model = MaterialModel::ValanisLandel;
    m.curvePreset.clear();
    m.fPrime = desc(c.fPrime);
    m.gPrime = desc(c.gPrime);
    m.hPrime = desc(c.hPrime);
}

std::shared_ptr<const TetConstraintModel> makeConstraintModel(const Material& m, const std::string& materialName) {
    const std::string ctx = "material '" + materialName + "'";
    if (auto why = validate(m); !why.empty()) throw InputError(ctx + ": " + why);
    switch (m.model) {
    case MaterialModel::StableNeoHookean:
        return std::make_shared<StableNeoHookeanModel>(m.mu(), m.lambda());
    case MaterialModel::NeoHookean:
    case MaterialModel::Linear:
    case MaterialModel::StVenantKirchhoff:
    case MaterialModel::Corotated:
        return std::make_shared<EnergyConstraintModel>(
            std::shared_ptr<const EnergyDensity>(makeEnergyDensity(materialModelName(m.model), m.mu(), m.lambda())));
    case MaterialModel::ValanisLandel: {
        ValanisLandelCurves curves = materialCurves(m, materialName);
        return std::make_shared<EnergyConstraintModel>(
            std::make_shared<const ValanisLandelDensity>(materialName, std::move(curves)));
    }
    }
    throw InputError(ctx + ": unknown model");
}

} // namespace viscera::sim
