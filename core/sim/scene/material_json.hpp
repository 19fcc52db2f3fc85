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
/// Read by sim::readMaterial (scene_json.hpp) for both files. Errors name the origin and the
/// JSON path ("scene.json: bodies[0].material.poisson_ratio: ..."); the material rules are
/// sim::validate(Material); curve rules are checked when the material becomes constraints.
#include "sim/material/material.hpp"

#include <string>
#include <string_view>

namespace viscera::sim {

/// One material object as JSON text (the studio's clipboard, tests). Throws viscera::InputError
/// ("<origin>: material.density: ...").
Material parseMaterial(std::string_view json, const std::string& origin);
std::string formatMaterial(const Material& m);

} // namespace viscera::sim
