#include "sim/clip/exp_map_rotation.hpp"

#include <Eigen/SVD>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace viscera::sim {

Mat3 expMapRotation(const Vec3& omega) {
    const double t2 = omega.squaredNorm();
    double a, b; // sin θ / θ and (1 − cos θ) / θ²
    if (t2 < 1e-8) {
        a = 1.0 - t2 / 6.0 + t2 * t2 / 120.0;
        b = 0.5 - t2 / 24.0 + t2 * t2 / 720.0;
    } else {
        const double t = std::sqrt(t2);
        a = std::sin(t) / t;
        b = (1.0 - std::cos(t)) / t2;
    }
    Mat3 K;
    K << 0, -omega.z(), omega.y(), omega.z(), 0, -omega.x(), -omega.y(), omega.x(), 0;
    return Mat3::Identity() + a * K + b * (K * K);
}

Vec3 expMapIncrement(const Mat3& A, const Mat3& R, double epsilon) {
    Vec3 num = Vec3::Zero();
    double den = 0;
    for (int k = 0; k < 3; ++k) {
        num += R.col(k).cross(A.col(k));
        den += R.col(k).dot(A.col(k));
    }
    return num / (std::abs(den) + epsilon);
}

int refineRotationExpMap(const Mat3& A, Mat3& R, const ExpMapOptions& o) {
    if (!A.allFinite()) return -1;
    int done = 0;
    for (int it = 0; it < o.maxIterations; ++it) {
        const Vec3 w = expMapIncrement(A, R, o.epsilon);
        if (!(w.norm() > o.tolerance)) break;
        Mat3 Rn = expMapRotation(w) * R;
        Rn = 0.5 * Rn * (3.0 * Mat3::Identity() - Rn.transpose() * Rn); // Newton–Schulz
        R = Rn;
        ++done;
    }
    return done;
}

Mat3 polarRotation(const Mat3& A) {
    if (!A.allFinite()) throw std::invalid_argument("sim::polarRotation(): A has a non-finite entry");
    Eigen::JacobiSVD<Mat3> svd(A, Eigen::ComputeFullU | Eigen::ComputeFullV);
    const Mat3 U = svd.matrixU(), V = svd.matrixV();
    Vec3 d(1, 1, (U * V.transpose()).determinant() < 0 ? -1.0 : 1.0);
    return U * d.asDiagonal() * V.transpose();
}

double rotationAngleBetween(const Mat3& Ra, const Mat3& Rb) {
    const Mat3 D = Ra.transpose() * Rb;
    // atan2(|axis·sin|, cos) is accurate at both ends, unlike acos((tr − 1)/2).
    const Vec3 s(D(2, 1) - D(1, 2), D(0, 2) - D(2, 0), D(1, 0) - D(0, 1));
    const double c = 0.5 * (D.trace() - 1.0);
    return std::atan2(0.5 * s.norm(), c);
}

} // namespace viscera::sim
