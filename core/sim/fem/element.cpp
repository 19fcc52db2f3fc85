#include "sim/fem/element.hpp"

#include "sim/clip/exp_map_rotation.hpp"

#include <Eigen/LU>
#include <Eigen/SVD>

#include <stdexcept>
#include <string>

namespace viscera::sim {

LinearTet makeLinearTet(const std::array<Vec3, 4>& x, double lambda, double mu) {
    LinearTet e;
    Mat3 dm;
    for (int k = 0; k < 3; ++k)
        dm.col(k) = x[k + 1] - x[0];
    e.volume = dm.determinant() / 6.0;
    if (!(e.volume > 0) || !std::isfinite(e.volume))
        throw std::invalid_argument("sim::makeLinearTet(): rest volume " + std::to_string(e.volume) +
                                    " m^3 must be positive");
    e.dmInv = dm.inverse();
    for (int a = 1; a < 4; ++a)
        e.grad.row(a) = e.dmInv.row(a - 1);
    e.grad.row(0) = -(e.grad.row(1) + e.grad.row(2) + e.grad.row(3));
    for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b) {
            const double dot = e.grad.row(a).dot(e.grad.row(b));
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j)
                    e.stiffness(3 * a + i, 3 * b + j) =
                        e.volume * (lambda * e.grad(a, i) * e.grad(b, j) + mu * e.grad(a, j) * e.grad(b, i) +
                                    (i == j ? mu * dot : 0.0));
        }
    return e;
}

double linearTetEnergy(const LinearTet& e, const Vec12& u, double lambda, double mu) {
    Mat3 gradU = Mat3::Zero(); // ∂u_i/∂x_j
    for (int a = 0; a < 4; ++a)
        gradU += u.segment<3>(3 * a) * e.grad.row(a);
    const Mat3 eps = 0.5 * (gradU + gradU.transpose());
    const double tr = eps.trace();
    return e.volume * (mu * eps.squaredNorm() + 0.5 * lambda * tr * tr);
}

Mat3 deformationGradient(const LinearTet& e, const std::array<Vec3, 4>& x) {
    Mat3 ds;
    for (int k = 0; k < 3; ++k)
        ds.col(k) = x[k + 1] - x[0];
    return ds * e.dmInv;
}

Mat3 elementRotation(const Mat3& F) {
    return F.allFinite() ? polarRotation(F) : Mat3::Identity();
}

} // namespace viscera::sim
