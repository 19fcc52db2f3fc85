#pragma once
/// Isotropic material parameters (SI units) and their conversions.
#include <string>

namespace viscera::sim {

enum class MaterialModel {
    NeoHookean, ///< stable Neo-Hookean (inversion-safe), XPBD constraints of Macklin & Müller 2021
};

struct Material {
    MaterialModel model = MaterialModel::NeoHookean;
    double youngsModulus = 3000.0; ///< Pa
    double poissonRatio = 0.45;    ///< dimensionless, in [0, 0.5)
    double density = 1050.0;       ///< kg/m^3

    double mu() const { return youngsModulus / (2.0 * (1.0 + poissonRatio)); }     ///< Pa
    double lambda() const {                                                          ///< Pa
        return youngsModulus * poissonRatio / ((1.0 + poissonRatio) * (1.0 - 2.0 * poissonRatio));
    }
};

/// Checks the parameters; returns an empty string when valid, otherwise the rule that failed,
/// e.g. "poisson_ratio 0.5 must be in [0, 0.5)".
std::string validate(const Material& m);

MaterialModel materialModelFromName(const std::string& name); ///< throws std::invalid_argument
std::string materialModelName(MaterialModel model);

} // namespace viscera::sim
