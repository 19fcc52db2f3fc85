#pragma once
// StepProblem fixtures built directly from box meshes (no XPBD solver involved).
#include "sim/material/stable_neo_hookean.hpp"
#include "sim/mesh/generators.hpp"
#include "sim/xpbd/step_problem.hpp"

#include <Eigen/Dense>

#include <functional>
#include <memory>

namespace viscera::sim::testing {

struct BlockSpec {
    BoxSpec box{Vec3::Zero(), Vec3(0.08, 0.02, 0.02), {4, 2, 2}};
    double youngsModulus = 20000; ///< Pa
    double poissonRatio = 0.45;
    double density = 1050; ///< kg/m^3
    double h = 1.0 / 60.0; ///< s
    Vec3 gravity = Vec3(0, 0, -9.81);
    /// Nodes with x below this are fixed (cantilever); negative: none fixed.
    double fixedBelowX = 1e-9;
};

/// One implicit step from rest with zero velocity: x̃ = x_rest + h² g on free nodes.
inline StepProblem makeBlockProblem(const BlockSpec& s) {
    auto mesh = makeBoxTetMesh(s.box);
    const double E = s.youngsModulus, nu = s.poissonRatio;
    const double mu = E / (2 * (1 + nu)), lambda = E * nu / ((1 + nu) * (1 - 2 * nu));
    StepProblem p;
    p.h = s.h;
    p.model = std::make_shared<StableNeoHookeanModel>(mu, lambda);
    const auto& x = mesh->positions();
    p.tets = mesh->tets();
    p.mass.assign(x.size(), 0.0);
    p.fixed.assign(x.size(), 0);
    for (const Tet& e : p.tets) {
        Mat3 dm;
        for (int k = 0; k < 3; ++k)
            dm.col(k) = x[e[k + 1]] - x[e[0]];
        p.dmInv.push_back(dm.inverse());
        p.volume.push_back(dm.determinant() / 6.0);
        p.weight.push_back(1.0);
        for (int32_t v : e)
            p.mass[v] += s.density * p.volume.back() / 4.0;
    }
    p.xTilde = x;
    for (size_t i = 0; i < x.size(); ++i) {
        p.fixed[i] = x[i].x() < s.fixedBelowX;
        if (!p.fixed[i]) p.xTilde[i] += s.h * s.h * s.gravity;
    }
    return p;
}

/// Rest positions of the block (the mesh's own).
inline std::vector<Vec3> restPositions(const BlockSpec& s) {
    return makeBoxTetMesh(s.box)->positions();
}

inline double maxDistance(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
    double d = 0;
    for (size_t i = 0; i < a.size(); ++i)
        d = std::max(d, (a[i] - b[i]).norm());
    return d;
}

inline double gradientInfNorm(const StepProblem& p, const std::vector<Vec3>& x) {
    std::vector<Vec3> g;
    p.gradientInto(x, g);
    double n = 0;
    for (const Vec3& v : g)
        n = std::max(n, v.cwiseAbs().maxCoeff());
    return n;
}

} // namespace viscera::sim::testing
