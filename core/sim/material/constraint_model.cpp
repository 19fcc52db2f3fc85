#include "sim/material/constraint_model.hpp"

namespace viscera::sim {

double TetConstraintModel::energyDensity(const Mat3& F) const {
    TetConstraintValues v;
    evaluate(F, v);
    const auto a = compliance();
    double e = 0;
    for (int k = 0; k < v.count; ++k)
        e += v.C[k] * v.C[k] / (2.0 * a[k]);
    return e;
}

Mat3 TetConstraintModel::energyDensityGradient(const Mat3& F) const {
    TetConstraintValues v;
    evaluate(F, v);
    const auto a = compliance();
    Mat3 g = Mat3::Zero();
    for (int k = 0; k < v.count; ++k)
        g += (v.C[k] / a[k]) * v.dCdF[k];
    return g;
}

} // namespace viscera::sim
