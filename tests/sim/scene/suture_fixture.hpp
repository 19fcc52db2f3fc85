#pragma once
// The small suturing scene of the scene tests (solver "fem"): two stacked slabs, a straight needle
// pushed down through both, the closure gauge on the pair.
#include "sim/mesh/generators.hpp"
#include "sim/suture/anastomosis.hpp"

#include <memory>
#include <string>
#include <vector>

namespace viscera::sim::suture_fixture {

inline constexpr const char* kScene = R"({
  "solver": {"type": "fem", "dt": 0.0333},
  "bodies": [
    {"name": "lower", "mesh": "meshes/lower.vtet", "fixed_nodes": [0, 1, 2, 3, 4, 5, 6, 7, 8],
     "material": {"model": "linear", "youngs_modulus": 60000, "poisson_ratio": 0.45, "density": 1000}},
    {"name": "upper", "mesh": "meshes/upper.vtet", "fixed_nodes": [0, 1, 2, 3, 4, 5, 6, 7, 8],
     "material": {"model": "linear", "youngs_modulus": 60000, "poisson_ratio": 0.45, "density": 1000}}],
  "suture": {"needle": {"shape": "straight", "length": 0.02, "puncture_force_n": 0.005},
             "thread": {"slack": 0.001},
             "trajectory": "tools/needle.traj", "gauge": ["lower", "upper"]}
})";

/// A straight needle above the two stacked slabs, pushed down `stepDown` m per frame.
inline std::string trajectory(int frames, double stepDown) {
    std::vector<NeedleFrame> out;
    for (int f = 0; f < frames; ++f) {
        NeedleFrame fr;
        fr.pose.linear() = Eigen::AngleAxisd(0.5 * 3.141592653589793, Vec3::UnitY()).toRotationMatrix(); // +x → −z
        fr.pose.translation() = Vec3(0.0051, 0.0049, 0.03 - stepDown * f);
        out.push_back(fr);
    }
    return formatTrajectory(out);
}

inline std::vector<std::unique_ptr<TetMesh>> slabs() {
    std::vector<std::unique_ptr<TetMesh>> v;
    v.push_back(makeBoxTetMesh({Vec3(0, 0, -0.003), Vec3(0.01, 0.01, 0.003), {4, 4, 2}}));
    v.push_back(makeBoxTetMesh({Vec3(0, 0, 0.001), Vec3(0.01, 0.01, 0.003), {4, 4, 2}}));
    return v;
}

} // namespace viscera::sim::suture_fixture
