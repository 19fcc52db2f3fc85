#include "sim/scene/scene_solver.hpp"

#include "sim/scene/fem_scene_solver.hpp"
#include "sim/scene/xpbd_scene_solver.hpp"

namespace viscera::sim {

std::unique_ptr<SceneSolver> makeSceneSolver(const SceneSolverInputs& in) {
    if (in.scene.solverType == "fem") return FemSceneSolver::create(in);
    return XpbdSceneSolver::create(in);
}

} // namespace viscera::sim
