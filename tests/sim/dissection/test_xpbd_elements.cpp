// XPBD element switches for dissection [A §5.3.1, §5.3.3]: a deactivated element exerts no force
// and stores no energy; a shrunk rest shape Fs·Dm is reached in equilibrium; results stay
// bit-identical across thread counts with elements switched off and reshaped.
#include "dissection_test_support.hpp"

#include <Eigen/Dense>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

using namespace viscera::sim;
using ::testing::HasSubstr;

namespace {

std::shared_ptr<StableNeoHookeanModel> snh(double E = 5000, double nu = 0.3) {
    return std::make_shared<StableNeoHookeanModel>(E / (2 * (1 + nu)), E * nu / ((1 + nu) * (1 - 2 * nu)));
}

XpbdSettings quiet(int threads = 1, bool simd = true) {
    XpbdSettings s;
    // A single free centimetre tet at 10 substeps keeps a small limit cycle (~1e-5 J) instead of
    // settling, with or without a changed rest shape; 40 substeps settle it to round-off.
    s.substeps = 40;
    s.gravity = Vec3::Zero();
    s.threads = threads;
    s.simd = simd;
    return s;
}

/// A rotation, so that the tests do not run in axis-aligned frames only.
Mat3 someRotation() {
    return (Eigen::AngleAxisd(0.4, Vec3(1, 2, 3).normalized())).toRotationMatrix();
}

double edgeLengthError(const std::vector<Vec3>& x, const std::vector<Vec3>& rest, const std::vector<int32_t>& v,
                       const Mat3& Fs) {
    double worst = 0;
    for (size_t a = 0; a < v.size(); ++a)
        for (size_t b = a + 1; b < v.size(); ++b) {
            const double target = (Fs * (rest[v[b]] - rest[v[a]])).norm();
            const double now = (x[v[b]] - x[v[a]]).norm();
            worst = std::max(worst, std::abs(now - target) / target);
        }
    return worst;
}

} // namespace

TEST(XpbdDissection, DeactivatedTetExertsNoForce) {
    for (bool simd : {true, false}) {
        auto tet =
            TetMesh::fromArrays({Vec3(0, 0, 0), Vec3(0.01, 0, 0), Vec3(0, 0.01, 0), Vec3(0, 0, 0.01)}, {{0, 1, 2, 3}});
        XpbdSystemDesc d;
        TetBodyDesc b;
        b.name = "t";
        b.mesh = tet.get();
        b.model = snh();
        d.tetBodies.push_back(b);
        auto sys = XpbdSystem::create(d, quiet(1, simd));
        // Stretch it: active, it pulls back; inactive, nothing moves.
        std::vector<Vec3> x = tet->positions();
        x[1].x() = 0.015;
        const std::vector<Vec3> v(4, Vec3::Zero());
        sys->setTetState(0, x, v);
        EXPECT_GT(sys->elasticEnergy(), 0);
        sys->setTetActive(0, 0, false);
        EXPECT_FALSE(sys->tetActive(0, 0));
        EXPECT_EQ(sys->elasticEnergy(), 0.0);
        for (int f = 0; f < 5; ++f)
            sys->step();
        for (int i = 0; i < 4; ++i)
            EXPECT_EQ(sys->tetPositions(0)[i], x[i]) << "simd " << simd;
        sys->setTetActive(0, 0, true);
        sys->step();
        EXPECT_LT(sys->tetPositions(0)[1].x(), 0.015);
    }
}

TEST(XpbdDissection, DeactivatedTriangleExertsNoForce) {
    const TriMesh tri = TriMesh::fromArrays({Vec3(0, 0, 0), Vec3(0.01, 0, 0), Vec3(0, 0.01, 0)}, {{0, 1, 2}});
    XpbdSystemDesc d;
    SurfaceBodyDesc s;
    s.name = "f";
    s.mesh = &tri;
    d.surfaces.push_back(s);
    auto sys = XpbdSystem::create(d, quiet());
    std::vector<Vec3> x = tri.positions();
    x[2].y() = 0.013;
    sys->setSurfaceState(0, x, std::vector<Vec3>(3, Vec3::Zero()));
    EXPECT_GT(sys->elasticEnergy(), 0);
    sys->setTriangleActive(0, 0, false);
    EXPECT_EQ(sys->elasticEnergy(), 0.0);
    for (int f = 0; f < 5; ++f)
        sys->step();
    for (int i = 0; i < 3; ++i)
        EXPECT_EQ(sys->surfacePositions(0)[i], x[i]);
    sys->setTriangleActive(0, 0, true);
    sys->step();
    EXPECT_LT(sys->surfacePositions(0)[2].y(), 0.013);
}

TEST(XpbdDissection, ShrunkTetRestShapeIsReachedInEquilibrium) {
    const Mat3 R = someRotation();
    const Mat3 Fs = R.transpose() * Vec3(0.5, 0.8, 1.0).asDiagonal() * R; // eq. 5.12
    for (bool simd : {true, false}) {
        auto tet = TetMesh::fromArrays(
            {Vec3(0, 0, 0), Vec3(0.01, 0, 0), Vec3(0.002, 0.01, 0), Vec3(0.001, 0.002, 0.01)}, {{0, 1, 2, 3}});
        XpbdSystemDesc d;
        TetBodyDesc b;
        b.name = "t";
        b.mesh = tet.get();
        b.model = snh();
        d.tetBodies.push_back(b);
        auto sys = XpbdSystem::create(d, quiet(1, simd));
        const double before = edgeLengthError(sys->tetPositions(0), tet->positions(), {0, 1, 2, 3}, Fs);
        EXPECT_GT(before, 0.2);
        sys->setTetRestShape(0, 0, Fs);
        EXPECT_GT(sys->elasticEnergy(), 0); // the rest state is now strained
        for (int f = 0; f < 300; ++f)
            ASSERT_TRUE(sys->step().finite);
        EXPECT_LT(edgeLengthError(sys->tetPositions(0), tet->positions(), {0, 1, 2, 3}, Fs), 1e-3) << "simd " << simd;
        EXPECT_LT(sys->elasticEnergy(), 1e-9);
        // Fs = I restores the original rest shape.
        sys->setTetRestShape(0, 0, Mat3::Identity());
        for (int f = 0; f < 300; ++f)
            sys->step();
        EXPECT_LT(edgeLengthError(sys->tetPositions(0), tet->positions(), {0, 1, 2, 3}, Mat3::Identity()), 1e-3);
    }
}

TEST(XpbdDissection, ShrunkTriangleRestShapeIsReachedInEquilibrium) {
    const TriMesh tri = TriMesh::fromArrays({Vec3(0, 0, 0), Vec3(0.01, 0, 0), Vec3(0.003, 0.01, 0)}, {{0, 1, 2}});
    XpbdSystemDesc d;
    SurfaceBodyDesc s;
    s.name = "f";
    s.mesh = &tri;
    d.surfaces.push_back(s);
    auto sys = XpbdSystem::create(d, quiet());
    // In-plane frame rotated by 30° about z: shrink 0.4 along one in-plane axis, 0.7 along the
    // other.
    const Mat3 R = Eigen::AngleAxisd(0.5236, Vec3::UnitZ()).toRotationMatrix().transpose();
    const Mat3 Fs = R.transpose() * Vec3(0.4, 0.7, 1.0).asDiagonal() * R;
    sys->setTriangleRestShape(0, 0, Fs);
    for (int f = 0; f < 300; ++f)
        ASSERT_TRUE(sys->step().finite);
    EXPECT_LT(edgeLengthError(sys->surfacePositions(0), tri.positions(), {0, 1, 2}, Fs), 1e-3);
}

TEST(XpbdDissection, SwitchedSystemIsBitIdenticalAcrossThreadCounts) {
    BoxSpec spec;
    spec.size = Vec3(0.04, 0.02, 0.02);
    spec.cells = {8, 4, 4};
    const auto box = makeBoxTetMesh(spec);
    auto run = [&](int threads) {
        XpbdSystemDesc d;
        TetBodyDesc b;
        b.name = "fat";
        b.mesh = box.get();
        b.model = snh(3000, 0.45);
        for (size_t i = 0; i < box->vertexCount(); ++i)
            if (box->positions()[i].x() < 1e-9) b.fixedNodes.push_back(int32_t(i));
        d.tetBodies.push_back(b);
        XpbdSettings set;
        set.threads = threads;
        auto sys = XpbdSystem::create(d, set);
        const Mat3 Fs = Vec3(0.3, 1.0, 1.0).asDiagonal();
        for (size_t t = 0; t < box->tetCount(); t += 3)
            sys->setTetActive(0, t, false);
        for (size_t t = 1; t < box->tetCount(); t += 5)
            sys->setTetRestShape(0, t, Fs);
        for (int f = 0; f < 20; ++f)
            EXPECT_TRUE(sys->step().finite);
        return sys->tetPositions(0);
    };
    const auto a = run(1), b = run(2), c = run(4);
    ASSERT_EQ(a.size(), b.size());
    for (size_t i = 0; i < a.size(); ++i) {
        ASSERT_TRUE(a[i].allFinite());
        ASSERT_EQ(a[i], b[i]) << i;
        ASSERT_EQ(a[i], c[i]) << i;
    }
}

TEST(XpbdDissection, StrainLimitsOfCutElementsAreOff) {
    // A triangle with a tight upper limit on ε_00: the limit holds the stretch while the triangle
    // is active and lets go when it is switched off.
    const TriMesh tri = TriMesh::fromArrays({Vec3(0, 0, 0), Vec3(0.01, 0, 0), Vec3(0, 0.01, 0)}, {{0, 1, 2}});
    XpbdSystemDesc d;
    SurfaceBodyDesc s;
    s.name = "f";
    s.mesh = &tri;
    s.stretchStiffness = 0;
    s.uv = {Vec2(0, 0), Vec2(1, 0), Vec2(0, 1)};
    TriStrainLimits sl;
    StrainLimit lim;
    lim.i = lim.j = 0;
    lim.upper = 0.01;
    sl.limits.push_back(lim);
    s.strainLimits = sl;
    s.fixedNodes = {0, 2};
    d.surfaces.push_back(s);
    auto sys = XpbdSystem::create(d, quiet());
    auto pull = [&] {
        std::vector<Vec3> x = sys->surfacePositions(0);
        std::vector<Vec3> v(3, Vec3::Zero());
        v[1] = Vec3(0.3, 0, 0); // m/s, away from the others
        sys->setSurfaceState(0, x, v);
        for (int f = 0; f < 10; ++f)
            sys->step();
        return sys->surfacePositions(0)[1].x();
    };
    EXPECT_LT(pull(), 0.0102);
    sys->setTriangleActive(0, 0, false);
    EXPECT_GT(pull(), 0.011);
}

TEST(XpbdDissection, BadRestShapeNamesTheElement) {
    const TriMesh tri = TriMesh::fromArrays({Vec3(0, 0, 0), Vec3(0.01, 0, 0), Vec3(0, 0.01, 0)}, {{0, 1, 2}});
    auto tet =
        TetMesh::fromArrays({Vec3(0, 0, 0), Vec3(0.01, 0, 0), Vec3(0, 0.01, 0), Vec3(0, 0, 0.01)}, {{0, 1, 2, 3}});
    XpbdSystemDesc d;
    SurfaceBodyDesc s;
    s.name = "f";
    s.mesh = &tri;
    d.surfaces.push_back(s);
    TetBodyDesc b;
    b.name = "t";
    b.mesh = tet.get();
    b.model = snh();
    d.tetBodies.push_back(b);
    auto sys = XpbdSystem::create(d, quiet());
    try {
        sys->setTetRestShape(0, 0, Mat3(Vec3(1, 1, -1).asDiagonal()));
        FAIL();
    } catch (const std::invalid_argument& e) {
        EXPECT_THAT(e.what(), HasSubstr("sim::XpbdSystem::setTetRestShape(): tet body 0 ('t'), tet 0: det Fs = -1"));
    }
    try {
        sys->setTriangleRestShape(0, 0, Mat3(Vec3(1, 0, 1).asDiagonal())); // flattens the triangle
        FAIL();
    } catch (const std::invalid_argument& e) {
        EXPECT_THAT(e.what(), HasSubstr("triangle 0: the shrunk rest triangle is degenerate"));
    }
    EXPECT_THROW(sys->setTetActive(0, 1, false), std::out_of_range);
    EXPECT_THROW(sys->setTriangleActive(1, 0, false), std::out_of_range);
    EXPECT_EQ(sys->tetCount(0), 1u);
    EXPECT_EQ(sys->triangleCount(0), 1u);
}
