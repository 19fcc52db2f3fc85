#pragma once
/// Material description (SI units) as authored in projects and carried by cases, and the factory
/// that turns it into XPBD tet constraints.
#include "sim/material/constraint_model.hpp"
#include "sim/material/valanis_landel.hpp"

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace viscera::sim {

enum class MaterialModel {
    StableNeoHookean,  ///< two constraints (deviatoric, hydrostatic), inversion-safe [Macklin & Müller 2021]
    NeoHookean,        ///< compressible Neo-Hookean [A Table 4.1], as C = sqrt(2Ψ)
    Linear,            ///< small-strain linear elasticity [A Table 4.1]
    StVenantKirchhoff, ///< [A Table 4.1]
    Corotated,         ///< corotated linear [A Table 4.1]
    ValanisLandel,     ///< Ψ = Σf(λi) + Σg(λiλj) + h(J) with curve-edited f′, g′, h′ [A eq. 4.15]
};

/// One Valanis–Landel curve: control points (x, y) with y in Pa; `unconstrained` lifts the
/// strictly-increasing rule (needed e.g. by the Neo-Hookean h′ beyond J ≈ e).
struct CurveDesc {
    std::vector<std::array<double, 2>> points;
    bool unconstrained = false;
};

struct Material {
    MaterialModel model = MaterialModel::StableNeoHookean;
    double youngsModulus = 3000.0; ///< Pa
    double poissonRatio = 0.45;    ///< dimensionless, in [0, 0.5)
    double density = 1050.0;       ///< kg/m^3
    /// Valanis–Landel only: either a preset generated from the Lamé parameters ("neo_hookean",
    /// "st_venant_kirchhoff", "corotated") or explicit curves (absent curve = 0).
    std::string curvePreset;
    std::optional<CurveDesc> fPrime, gPrime, hPrime;

    double mu() const { return youngsModulus / (2.0 * (1.0 + poissonRatio)); } ///< Pa
    double lambda() const {                                                    ///< Pa
        return youngsModulus * poissonRatio / ((1.0 + poissonRatio) * (1.0 - 2.0 * poissonRatio));
    }
};

/// Checks the scalar parameters; returns an empty string when valid, otherwise the rule that
/// failed, e.g. "poisson_ratio 0.5 must be in [0, 0.5)".
/// Admissible ranges of the material numbers: validate() and the scene reader use these.
struct MaterialLimits {
    static constexpr double maxYoungsModulus = 1e12; ///< Pa; youngs_modulus in (0, max]
    static constexpr double maxPoissonRatio = 0.5;   ///< poisson_ratio in [0, max)
    static constexpr double maxDensity = 1e5;        ///< kg/m^3; density in (0, max]
};
std::string validate(const Material& m);

MaterialModel materialModelFromName(const std::string& name); ///< throws std::invalid_argument
std::string materialModelName(MaterialModel model);
/// All model names, for messages and editors.
const std::vector<std::string>& materialModelNames();

/// The Valanis–Landel curves of a material (model valanis_landel): its preset generated from the
/// Lamé parameters, or its explicit curves (absent curve = zero term). Throws viscera::InputError
/// naming the material, the curve and the control point (the rules of makeConstraintModel).
ValanisLandelCurves materialCurves(const Material& m, const std::string& materialName);

/// Makes `m` a Valanis–Landel material with explicit curves `c` (the preset name cleared; an
/// absent curve stays absent): what the studio's curve editor, presets and fit write.
void setMaterialCurves(Material& m, const ValanisLandelCurves& c);

/// Builds the constraint model of a material. Throws viscera::InputError naming `materialName`,
/// the curve and the control point for invalid curves (not increasing, stress at rest not zero).
std::shared_ptr<const TetConstraintModel> makeConstraintModel(const Material& m, const std::string& materialName);

} // namespace viscera::sim
