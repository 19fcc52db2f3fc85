#include "sim/mesh/generators.hpp"
#include "sim/mesh/tri_mesh.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <numbers>

using namespace viscera::sim;
using ::testing::HasSubstr;

TEST(TriMesh, EllipsoidIsClosedWithVolumeNearAnalytic) {
    TriMesh s = makeEllipsoidSurface(Vec3(1, 2, 3), Vec3(0.3, 0.2, 0.1), 64, 32);
    EXPECT_TRUE(s.isClosedOriented());
    const double exact = 4.0 / 3.0 * std::numbers::pi * 0.3 * 0.2 * 0.1;
    EXPECT_NEAR(s.signedVolume(), exact, 0.01 * exact);
    auto [lo, hi] = s.bounds();
    EXPECT_NEAR(hi.z() - lo.z(), 0.2, 1e-12);
}

TEST(TriMesh, BoxSurfaceVolumeAndArea) {
    TriMesh s = makeBoxSurface(Vec3(0, 0, 0), Vec3(1, 2, 3));
    EXPECT_TRUE(s.isClosedOriented());
    EXPECT_NEAR(s.signedVolume(), 6.0, 1e-12);
    EXPECT_NEAR(s.area(), 2 * (2 + 3 + 6), 1e-12);
    EXPECT_NEAR(s.triangleNormal(0).norm(), 1.0, 1e-12);
}

TEST(TriMesh, OpenSurfaceIsNotClosed) {
    TriMesh s = TriMesh::fromArrays({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)}, {{0, 1, 2}});
    EXPECT_FALSE(s.isClosedOriented());
}

TEST(TriMesh, RejectsBadInput) {
    std::vector<Vec3> p = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
    try {
        TriMesh::fromArrays(p, {{0, 1, 5}}, "skin.obj");
        FAIL();
    } catch (const std::invalid_argument& e) {
        EXPECT_THAT(e.what(), HasSubstr("skin.obj: triangle 0 references vertex 5 (mesh has 3 vertices)"));
    }
    EXPECT_THROW(TriMesh::fromArrays(p, {}), std::invalid_argument);
    EXPECT_THROW(TriMesh::fromArrays(p, {{0, 0, 1}}), std::invalid_argument);
    p[1].x() = std::numeric_limits<double>::infinity();
    EXPECT_THROW(TriMesh::fromArrays(p, {{0, 1, 2}}), std::invalid_argument);
}

TEST(TriMesh, LiverAndTubeSurfacesAreClosedAndOutward) {
    TriMesh liver = makeLiverSurface(Vec3::Zero(), Vec3(0.1, 0.07, 0.04), 0.5, 48, 24);
    EXPECT_TRUE(liver.isClosedOriented());
    EXPECT_GT(liver.signedVolume(), 0.0);
    // The wedge makes it smaller than the ellipsoid it starts from.
    EXPECT_LT(liver.signedVolume(), 4.0 / 3.0 * std::numbers::pi * 0.1 * 0.07 * 0.04);
    TriMesh tube = makeTubeSurface(Vec3(0, 0, 0), Vec3(0.1, 0.02, 0), 0.005, 32, 8);
    EXPECT_TRUE(tube.isClosedOriented());
    const double exact = std::numbers::pi * 0.005 * 0.005 * std::hypot(0.1, 0.02);
    EXPECT_NEAR(tube.signedVolume(), exact, 0.01 * exact);
}
