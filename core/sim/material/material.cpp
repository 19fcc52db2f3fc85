#include "sim/material/material.hpp"

#include <cmath>
#include <stdexcept>

namespace viscera::sim {

std::string validate(const Material& m) {
    if (!std::isfinite(m.youngsModulus) || m.youngsModulus <= 0 || m.youngsModulus > 1e12)
        return "youngs_modulus " + std::to_string(m.youngsModulus) + " must be in (0, 1e12] Pa";
    if (!std::isfinite(m.poissonRatio) || m.poissonRatio < 0 || m.poissonRatio >= 0.5)
        return "poisson_ratio " + std::to_string(m.poissonRatio) + " must be in [0, 0.5)";
    if (!std::isfinite(m.density) || m.density <= 0 || m.density > 1e5)
        return "density " + std::to_string(m.density) + " must be in (0, 1e5] kg/m^3";
    return {};
}

MaterialModel materialModelFromName(const std::string& name) {
    if (name == "neo_hookean") return MaterialModel::NeoHookean;
    throw std::invalid_argument("unknown material model '" + name + "' (supported: neo_hookean)");
}

std::string materialModelName(MaterialModel model) {
    switch (model) {
    case MaterialModel::NeoHookean: return "neo_hookean";
    }
    return "unknown";
}

} // namespace viscera::sim
