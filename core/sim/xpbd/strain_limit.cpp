#include "sim/xpbd/strain_limit.hpp"

#include <Eigen/Dense>

#include <cmath>

namespace viscera::sim {
namespace {

/// ε_ij of F = D_s M with D columns d_k = x_{k+1} − x_0 (D = 2 or 3 edges), and its gradient.
template <int D, class MatM> double greenStrainEntry(const Vec3* x, const MatM& M, int i, int j, Vec3* grad) {
    Eigen::Matrix<double, 3, D> ds;
    for (int k = 0; k < D; ++k)
        ds.col(k) = x[k + 1] - x[0];
    const Eigen::Matrix<double, 3, D> F = ds * M;
    const double eps = 0.5 * (F.col(i).dot(F.col(j)) - (i == j ? 1.0 : 0.0));
    if (grad) {
        grad[0].setZero();
        for (int k = 0; k < D; ++k) {
            grad[k + 1] = 0.5 * (M(k, i) * F.col(j) + M(k, j) * F.col(i));
            grad[0] -= grad[k + 1];
        }
    }
    return eps;
}

} // namespace

std::string validate(const StrainLimit& s, int dim) {
    if (s.i < 0 || s.i >= dim || s.j < 0 || s.j >= dim)
        return "strain entry (" + std::to_string(s.i) + ", " + std::to_string(s.j) + ") must be in [0, " +
               std::to_string(dim - 1) + "]";
    if (std::isnan(s.lower) || std::isnan(s.upper)) return "strain limits must not be NaN";
    if (std::isinf(s.lower) && std::isinf(s.upper)) return "a strain limit needs a finite lower or upper bound";
    if (s.lower == std::numeric_limits<double>::infinity() || s.upper == -std::numeric_limits<double>::infinity())
        return "lower must not be +inf and upper must not be -inf";
    if (s.lower > s.upper) return "strain limit lower must not exceed upper";
    if (!std::isfinite(s.compliance) || s.compliance < 0) return "strain limit compliance must be finite and >= 0";
    return {};
}

std::string validateAxes(const Mat3& axes) {
    if (!axes.allFinite()) return "material axes must be finite";
    if (((axes.transpose() * axes) - Mat3::Identity()).cwiseAbs().maxCoeff() > 1e-9)
        return "material axes must be orthonormal columns";
    return {};
}

Mat3 tetMaterialDmInv(const std::array<Vec3, 4>& rest, const Mat3& axes) {
    Mat3 dm;
    for (int k = 0; k < 3; ++k)
        dm.col(k) = rest[k + 1] - rest[0];
    return dm.inverse() * axes;
}

double tetGreenStrain(const std::array<Vec3, 4>& x, const Mat3& M, int i, int j, std::array<Vec3, 4>* grad) {
    return greenStrainEntry<3>(x.data(), M, i, j, grad ? grad->data() : nullptr);
}

bool triangleUvDmInv(const std::array<Vec3, 3>& rest, const std::array<Vec2, 3>& uv, Mat2& M) {
    Eigen::Matrix<double, 3, 2> e;
    e.col(0) = rest[1] - rest[0];
    e.col(1) = rest[2] - rest[0];
    Mat2 u;
    u.col(0) = uv[1] - uv[0];
    u.col(1) = uv[2] - uv[0];
    const double area2 = e.col(0).cross(e.col(1)).norm();
    const double scale = e.col(0).squaredNorm() + e.col(1).squaredNorm();
    if (!(area2 > 1e-12 * scale) || !(std::abs(u.determinant()) > 1e-14 * u.squaredNorm())) return false;
    const Eigen::Matrix<double, 3, 2> tb = e * u.inverse(); // (T, B), eq. 4.23
    const double tn = tb.col(0).norm();
    if (!(tn > 0)) return false;
    const Vec3 t = tb.col(0) / tn;
    Vec3 b = tb.col(1) - tb.col(1).dot(t) * t;
    const double bn = b.norm();
    if (!(bn > 1e-12 * tb.col(1).norm())) return false;
    b /= bn;
    Eigen::Matrix<double, 3, 2> frame;
    frame.col(0) = t;
    frame.col(1) = b;
    const Mat2 dm = frame.transpose() * e; // D'_m, eq. 4.24
    if (!(std::abs(dm.determinant()) > 0)) return false;
    M = dm.inverse();
    return M.allFinite();
}

double triGreenStrain(const std::array<Vec3, 3>& x, const Mat2& M, int i, int j, std::array<Vec3, 3>* grad) {
    return greenStrainEntry<2>(x.data(), M, i, j, grad ? grad->data() : nullptr);
}

} // namespace viscera::sim
