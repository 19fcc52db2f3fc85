#include "sim/xpbd/step_problem.hpp"

namespace viscera::sim {

Mat3 StepProblem::deformationGradient(const std::vector<Vec3>& x, size_t t) const {
    const Tet& e = tets[t];
    Mat3 ds;
    for (int k = 0; k < 3; ++k)
        ds.col(k) = x[e[k + 1]] - x[e[0]];
    return ds * dmInv[t];
}

double StepProblem::objective(const std::vector<Vec3>& x) const {
    double inertia = 0;
    for (size_t i = 0; i < x.size(); ++i)
        inertia += 0.5 * mass[i] * (x[i] - xTilde[i]).squaredNorm();
    double elastic = 0;
    for (size_t t = 0; t < tets.size(); ++t)
        elastic += volume[t] * weight[t] * model->energyDensity(deformationGradient(x, t));
    return inertia + h * h * elastic;
}

void StepProblem::gradientInto(const std::vector<Vec3>& x, std::vector<Vec3>& g) const {
    g.resize(x.size());
    for (size_t i = 0; i < x.size(); ++i)
        g[i] = mass[i] * (x[i] - xTilde[i]);
    for (size_t t = 0; t < tets.size(); ++t) {
        // dE/dx_k = V w P Dm^-T column k (k = 1..3); dE/dx_0 = -sum.
        const Mat3 G = (h * h * volume[t] * weight[t]) * model->energyDensityGradient(deformationGradient(x, t)) *
                       dmInv[t].transpose();
        const Tet& e = tets[t];
        g[e[0]] -= G.col(0) + G.col(1) + G.col(2);
        for (int k = 0; k < 3; ++k)
            g[e[k + 1]] += G.col(k);
    }
    for (size_t i = 0; i < x.size(); ++i)
        if (fixed[i]) g[i].setZero();
}

double relativeError(double fk, double f0, double fStar) {
    const double den = f0 - fStar;
    return den == 0 ? 0.0 : (fk - fStar) / den;
}

} // namespace viscera::sim
