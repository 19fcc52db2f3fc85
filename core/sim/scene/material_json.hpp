#pragma once
/// The "material" object shared by project.json and a case's scene.json:
///
///   {"model": "stable_neo_hookean" | "neo_hookean" | "linear" | "st_venant_kirchhoff" |
///             "corotated" | "valanis_landel",
///    "youngs_modulus": 3000, "poisson_ratio": 0.45, "density": 1050,
///    "curves": {"preset": "neo_hookean"}                              (valanis_landel only)
///           | {"f_prime": {"points": [[0.5, -900], [1, 0], [2, 2400]]},
///              "h_prime": {"points": [...], "unconstrained": true}}}
///
/// Errors name the origin and the field path ("scene.json: bodies[0].material.poisson_ratio:
/// ..."); curve rules are checked when the material is turned into constraints.
#include "sim/material/material.hpp"

#include <nlohmann/json_fwd.hpp>

#include <string>

namespace viscera::sim {

/// Throws viscera::InputError.
Material parseMaterial(const nlohmann::json& j, const std::string& path, const std::string& origin);
nlohmann::json materialToJson(const Material& m);

} // namespace viscera::sim
