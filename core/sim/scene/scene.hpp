#pragma once
/// Scene description carried by a case (scene.json): the solver settings and the bodies.
/// Parsing is strict; every error names the origin, the field and the rule.
///
/// {
///   "solver": {"type": "xpbd", "dt": 0.0166667, "substeps": 10, "iterations": 1,
///              "damping": 1.0, "max_speed": 20.0},
///   "gravity": [0, 0, -9.81],
///   "instructions": "Watch the slab settle under gravity.",
///   "bodies": [{"name": "slab", "mesh": "meshes/slab.vtet",
///               "material": {"model": "neo_hookean", "youngs_modulus": 3000,
///                            "poisson_ratio": 0.45, "density": 1050},
///               "fixed_nodes": [0, 1, 2]}]
/// }
#include "sim/material/material.hpp"
#include "sim/xpbd/xpbd_solver.hpp"

#include <string>
#include <string_view>
#include <vector>

namespace viscera::sim {

struct BodyDesc {
    std::string name;
    std::string meshPath; ///< path of the .vtet inside the case
    Material material;
    std::vector<int32_t> fixedNodes;
};

struct SceneDesc {
    std::string instructions; ///< shown to the trainee; may be empty
    std::string solverType = "xpbd";
    XpbdSettings xpbd;
    std::vector<BodyDesc> bodies;
};

/// Throws viscera::InputError ("scene.json: bodies[0].material.poisson_ratio: must be in [0, 0.5)").
SceneDesc parseScene(std::string_view json, const std::string& origin);
std::string formatScene(const SceneDesc& scene);

} // namespace viscera::sim
