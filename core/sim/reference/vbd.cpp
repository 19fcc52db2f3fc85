#include "sim/reference/vbd.hpp"

#include "sim/reference/newton.hpp"

#include <Eigen/Eigenvalues>

#include <array>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

namespace viscera::sim {
namespace {

/// Gradient of tet t's term with respect to its node `a` (0..3) at xe.
Vec3 nodeGradient(const StepProblem& p, size_t t, int a, const std::array<Vec3, 4>& xe, double scale) {
    const Mat3 G = tetTermGradientColumns(p, t, xe, scale);
    return a == 0 ? Vec3(-(G.col(0) + G.col(1) + G.col(2))) : Vec3(G.col(a - 1));
}

/// Each node's tets and its place in them.
std::vector<std::vector<std::pair<uint32_t, uint8_t>>> nodeTets(const StepProblem& p) {
    std::vector<std::vector<std::pair<uint32_t, uint8_t>>> out(p.xTilde.size());
    for (size_t t = 0; t < p.tets.size(); ++t)
        for (int a = 0; a < 4; ++a) {
            const int32_t v = p.tets[t][a];
            if (v < 0 || static_cast<size_t>(v) >= out.size())
                throw std::invalid_argument("sim::iterateVbd(): tet " + std::to_string(t) + " references node " +
                                            std::to_string(v) + " (problem has " + std::to_string(out.size()) +
                                            " nodes)");
            out[static_cast<size_t>(v)].emplace_back(static_cast<uint32_t>(t), static_cast<uint8_t>(a));
        }
    return out;
}

/// One block step of node i: x_i ← x_i − H_i⁻¹ g_i (unchanged when H_i is not invertible).
void relaxNode(const StepProblem& p, std::vector<Vec3>& x, size_t i,
               const std::vector<std::pair<uint32_t, uint8_t>>& tets, double fdStep) {
    const double h2 = p.h * p.h;
    Vec3 g = p.mass[i] * (x[i] - p.xTilde[i]);
    Mat3 He = Mat3::Zero();
    for (const auto& [t, a] : tets) {
        const double scale = h2 * p.volume[t] * p.weight[t];
        if (scale == 0) continue;
        const Tet& e = p.tets[t];
        std::array<Vec3, 4> xe = {x[e[0]], x[e[1]], x[e[2]], x[e[3]]};
        g += nodeGradient(p, t, a, xe, scale);
        const double step = fdStep * std::cbrt(6.0 * p.volume[t]);
        for (int d = 0; d < 3; ++d) {
            const double x0 = xe[a][d];
            xe[a][d] = x0 + step;
            const Vec3 gp = nodeGradient(p, t, a, xe, scale);
            xe[a][d] = x0 - step;
            const Vec3 gm = nodeGradient(p, t, a, xe, scale);
            xe[a][d] = x0;
            He.col(d) += (gp - gm) / (2 * step);
        }
    }
    const Eigen::SelfAdjointEigenSolver<Mat3> eig(0.5 * (He + He.transpose()));
    const Vec3 lambda = eig.eigenvalues().cwiseMax(0.0).array() + p.mass[i];
    if (!(lambda.minCoeff() > 0) || !g.allFinite()) return;
    const Mat3& Q = eig.eigenvectors();
    const Vec3 dx = -(Q * (Q.transpose() * g).cwiseQuotient(lambda));
    if (dx.allFinite()) x[i] += dx;
}

} // namespace

void iterateVbd(const StepProblem& p, int iterations, const VbdObserver& observe, double fdStep) {
    const std::string where = "sim::iterateVbd(): ";
    if (iterations < 1) throw std::invalid_argument(where + "iterations must be >= 1");
    const size_t nv = p.xTilde.size(), nt = p.tets.size();
    if (p.mass.size() != nv || p.fixed.size() != nv)
        throw std::invalid_argument(where + "xTilde, mass and fixed must have one entry per node");
    if (p.dmInv.size() != nt || p.volume.size() != nt || p.weight.size() != nt || !p.model)
        throw std::invalid_argument(where + "dmInv, volume and weight need one entry per tet, and a model");
    const auto adjacency = nodeTets(p);
    std::vector<Vec3> x = p.xTilde;
    double seconds = 0;
    for (int k = 1; k <= iterations; ++k) {
        const auto t0 = std::chrono::steady_clock::now();
        for (size_t i = 0; i < nv; ++i)
            if (!p.fixed[i] && p.mass[i] > 0) relaxNode(p, x, i, adjacency[i], fdStep);
        seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        if (observe) observe(k, x, seconds);
    }
}

AccuracyTrace measureVbd(const StepProblem& problem, int iterations, const NewtonSettings& settings) {
    const NewtonResult reference = solveNewton(problem, problem.xTilde, settings);
    AccuracyRecorder recorder("vbd", problem, reference, problem.xTilde);
    iterateVbd(problem, iterations,
               [&](int k, const std::vector<Vec3>& xk, double seconds) { recorder.observe(k, xk, seconds); });
    return recorder.take();
}

} // namespace viscera::sim
