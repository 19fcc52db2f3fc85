#include "sim/xpbd/membrane.hpp"

#include <Eigen/Dense>

#include <cmath>

namespace viscera::sim {

bool triangleRestDmInv(const std::array<Vec3, 3>& rest, Mat2& M) {
    const Vec3 e1 = rest[1] - rest[0], e2 = rest[2] - rest[0];
    const double l1 = e1.norm();
    const double area2 = e1.cross(e2).norm();
    if (!(l1 > 0) || !(area2 > 1e-12 * (e1.squaredNorm() + e2.squaredNorm()))) return false;
    const Vec3 t = e1 / l1;
    const Vec3 b = (e2 - e2.dot(t) * t).normalized();
    Mat2 dm;
    dm << l1, e2.dot(t), 0.0, e2.dot(b);
    M = dm.inverse();
    return M.allFinite();
}

std::array<double, 3> membraneConstraints(const std::array<Vec3, 3>& x, const Mat2& M,
                                          std::array<std::array<Vec3, 3>, 3>* grad) {
    static const double kSqrt2 = std::sqrt(2.0);
    std::array<double, 3> c;
    c[0] = triGreenStrain(x, M, 0, 0, grad ? &(*grad)[0] : nullptr);
    c[1] = triGreenStrain(x, M, 1, 1, grad ? &(*grad)[1] : nullptr);
    c[2] = kSqrt2 * triGreenStrain(x, M, 0, 1, grad ? &(*grad)[2] : nullptr);
    if (grad)
        for (Vec3& g : (*grad)[2])
            g *= kSqrt2;
    return c;
}

} // namespace viscera::sim
