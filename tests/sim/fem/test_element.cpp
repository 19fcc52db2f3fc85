#include "sim/fem/element.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <random>

using namespace viscera::sim;

namespace {

std::array<Vec3, 4> randomTet(std::mt19937& rng) {
    std::uniform_real_distribution<double> u(-0.3, 0.3);
    std::array<Vec3, 4> x = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
    for (auto& p : x)
        p = 0.01 * (p + Vec3(u(rng), u(rng), u(rng)));
    Mat3 dm;
    for (int k = 0; k < 3; ++k)
        dm.col(k) = x[k + 1] - x[0];
    if (dm.determinant() < 0) std::swap(x[1], x[2]);
    return x;
}

} // namespace

// K_e must be the Hessian of the element energy: central differences of the energy's gradient,
// itself by central differences of the energy (the energy is quadratic, so both are exact up to
// rounding), over a sweep of shapes and materials.
TEST(FemElement, StiffnessIsEnergyHessianByFiniteDifferences) {
    std::mt19937 rng(11);
    for (double nu : {0.0, 0.3, 0.45, 0.49})
        for (double E : {1e3, 5e4, 1e6})
            for (int trial = 0; trial < 4; ++trial) {
                const double mu = E / (2 * (1 + nu)), lambda = E * nu / ((1 + nu) * (1 - 2 * nu));
                const LinearTet e = makeLinearTet(randomTet(rng), lambda, mu);
                Vec12 u0 = Vec12::Random() * 1e-3;
                const double h = 1e-4;
                Mat12 H;
                for (int i = 0; i < 12; ++i)
                    for (int j = 0; j < 12; ++j) {
                        auto f = [&](double di, double dj) {
                            Vec12 u = u0;
                            u[i] += di;
                            u[j] += dj;
                            return linearTetEnergy(e, u, lambda, mu);
                        };
                        H(i, j) = (f(h, h) - f(h, -h) - f(-h, h) + f(-h, -h)) / (4 * h * h);
                    }
                const double scale = e.stiffness.cwiseAbs().maxCoeff();
                EXPECT_LT((H - e.stiffness).cwiseAbs().maxCoeff(), 1e-6 * scale) << "E " << E << " nu " << nu;
                // Rigid translations produce no force.
                Vec12 t;
                for (int a = 0; a < 4; ++a)
                    t.segment<3>(3 * a) = Vec3(0.3, -0.2, 0.7);
                EXPECT_LT((e.stiffness * t).norm(), 1e-9 * scale);
            }
}

TEST(FemElement, PolarRotationRecoversTheRotation) {
    std::mt19937 rng(3);
    for (int trial = 0; trial < 50; ++trial) {
        const Mat3 R = Eigen::Quaterniond(Eigen::Vector4d::Random().normalized()).toRotationMatrix();
        Mat3 S = Mat3::Random();
        S = (0.1 * (S + S.transpose()) + Mat3::Identity()).eval(); // symmetric positive stretch
        const Mat3 Rp = elementRotation(R * S);
        EXPECT_LT((Rp - R).norm(), 1e-9);
        EXPECT_NEAR(Rp.determinant(), 1.0, 1e-12);
    }
    // Corotated element force vanishes under a rigid motion: R K (Rᵀx − x0) = 0.
    const std::array<Vec3, 4> x0 = randomTet(rng);
    const LinearTet e = makeLinearTet(x0, 1e4, 2e4);
    const Mat3 R = Eigen::AngleAxisd(1.1, Vec3(1, 2, 3).normalized()).toRotationMatrix();
    std::array<Vec3, 4> x;
    for (int a = 0; a < 4; ++a)
        x[a] = R * x0[a] + Vec3(0.1, 0.2, 0.3);
    const Mat3 Re = elementRotation(deformationGradient(e, x));
    EXPECT_LT((Re - R).norm(), 1e-10);
    Vec12 d;
    for (int a = 0; a < 4; ++a)
        d.segment<3>(3 * a) = Re.transpose() * x[a] - x0[a];
    Vec12 dc = d;
    for (int a = 0; a < 4; ++a)
        dc.segment<3>(3 * a) -= d.segment<3>(0); // remove the translation
    EXPECT_LT((e.stiffness * d).norm(), 1e-9 * e.stiffness.norm() * 1e-2);
    EXPECT_EQ(elementRotation(Mat3::Constant(std::numeric_limits<double>::quiet_NaN())), Mat3::Identity());
    EXPECT_THROW(makeLinearTet({x0[0], x0[2], x0[1], x0[3]}, 1, 1), std::invalid_argument);
}
