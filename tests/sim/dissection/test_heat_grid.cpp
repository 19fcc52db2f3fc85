// Heat grid [A §5.3.2, eq. 5.9–5.10]: stable substeps, one explicit step against the stencil,
// maximum principle, exact shifts when the tool moves, trilinear interpolation.
#include "sim/dissection/heat_grid.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace viscera::sim;
using ::testing::HasSubstr;

namespace {

HeatGridSettings smallGrid() {
    HeatGridSettings s;
    s.nodes = 10;
    s.spacing = 0.5e-3;
    return s;
}

size_t node(const HeatGrid& g, int i, int j, int k) {
    const size_t n = size_t(g.settings().nodes);
    return (size_t(k) * n + j) * n + i;
}

} // namespace

TEST(HeatGrid, SubstepsRespectTheStabilityLimit) {
    HeatGrid g(HeatGridSettings{});
    const double h = 0.5e-3 * 0.5e-3 / (6 * 4.2e-6);
    EXPECT_DOUBLE_EQ(g.stableSubstep(), h);
    EXPECT_EQ(g.substepsFor(1.0 / 60.0), int(std::ceil((1.0 / 60.0) / h))); // 2
    EXPECT_EQ(g.substepsFor(1.0 / 60.0), 2);
    EXPECT_EQ(g.substepsFor(0.5 * h), 1);
    EXPECT_EQ(g.substepsFor(1.0), int(std::ceil(1.0 / h)));
}

TEST(HeatGrid, OneSubstepMatchesTheFiniteDifferenceStencil) {
    HeatGrid g(smallGrid());
    const double dl = 0.5e-3, body = 37, T = 170;
    // A source smaller than the spacing, on a lattice node: only that node is held hot.
    const Vec3 c(10 * dl, -4 * dl, 3 * dl);
    const double h = g.stableSubstep(); // r = α h / dl² = 1/6
    EXPECT_EQ(g.advance({c, 0.1 * dl, T}, h), 1);
    const Vec3 o = g.origin();
    const int ci = int(std::lround((c.x() - o.x()) / dl)), cj = int(std::lround((c.y() - o.y()) / dl)),
              ck = int(std::lround((c.z() - o.z()) / dl));
    EXPECT_EQ(ci, 5);
    const auto& u = g.values();
    EXPECT_DOUBLE_EQ(u[node(g, ci, cj, ck)], T);
    // Face neighbours: u + r (T − u) with r = 1/6; edge and corner neighbours stay at body.
    for (int a = 0; a < 3; ++a)
        for (int s : {-1, 1}) {
            int d[3] = {0, 0, 0};
            d[a] = s;
            EXPECT_NEAR(u[node(g, ci + d[0], cj + d[1], ck + d[2])], body + (T - body) / 6.0, 1e-12);
        }
    EXPECT_DOUBLE_EQ(u[node(g, ci + 1, cj + 1, ck)], body);
    EXPECT_DOUBLE_EQ(u[node(g, ci + 1, cj + 1, ck + 1)], body);
    // A second substep: the face neighbour gets r·Σ(neighbours − u) from the values above.
    const double u1 = body + (T - body) / 6.0;
    g.advance({c, 0.1 * dl, T}, h);
    const double expect = u1 + (T + 4 * body + body - 6 * u1) / 6.0;
    EXPECT_NEAR(g.values()[node(g, ci + 1, cj, ck)], expect, 1e-12);
    // Diagonal neighbour (ci+1, cj+1): two face neighbours at u1.
    EXPECT_NEAR(g.values()[node(g, ci + 1, cj + 1, ck)], body + 2 * (u1 - body) / 6.0, 1e-12);
}

TEST(HeatGrid, MaximumPrincipleHoldsForAMovingToolAndAnyTimeStep) {
    HeatGrid g(HeatGridSettings{});
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> U(-1, 1);
    Vec3 c = Vec3::Zero();
    for (int f = 0; f < 300; ++f) {
        c += 1e-3 * Vec3(U(rng), U(rng), U(rng));
        const double T = 37 + 133 * (0.5 + 0.5 * U(rng));  // [37, 170]
        const double dt = f % 50 == 49 ? 0.5 : 1.0 / 60.0; // now and then a huge step
        g.advance({c, 0.5e-3 + 1e-3 * (0.5 + 0.5 * U(rng)), T}, dt);
        for (double v : g.values()) {
            ASSERT_TRUE(std::isfinite(v));
            ASSERT_GE(v, 37.0 - 1e-12) << "frame " << f;
            ASSERT_LE(v, 170.0 + 1e-12) << "frame " << f;
        }
        if (f % 3 == 0) {
            g.advanceUnheated(c, 1.0 / 60.0);
            EXPECT_GE(g.minTemperature(), 37.0 - 1e-12);
            EXPECT_LE(g.maxTemperature(), 170.0 + 1e-12);
        }
    }
    // Heat spreads: some node off the sphere is warmer than the body.
    g.advance({c, 1e-3, 170}, 0.2);
    const Vec3 probe = c + Vec3(1.4e-3, 0, 0);
    EXPECT_GT(g.temperatureAt(probe), 37.5);
    EXPECT_LT(g.temperatureAt(probe), 170.0);
}

TEST(HeatGrid, ShiftsByWholeNodesWhenTheToolMoves) {
    HeatGrid g(smallGrid());
    const double dl = 0.5e-3;
    const Vec3 c(0, 0, 0);
    g.advance({c, 1.2 * dl, 170}, 0.05);
    const std::vector<double> before = g.values();
    const Vec3 o0 = g.origin();
    g.advanceUnheated(c + Vec3(2 * dl, -dl, 0), 0.0); // no diffusion: a pure shift
    const Vec3 o1 = g.origin();
    EXPECT_NEAR(o1.x() - o0.x(), 2 * dl, 1e-15);
    EXPECT_NEAR(o1.y() - o0.y(), -dl, 1e-15);
    const int n = g.settings().nodes;
    for (int k = 1; k < n - 1; ++k)
        for (int j = 2; j < n - 1; ++j)
            for (int i = 1; i < n - 3; ++i)
                ASSERT_EQ(g.values()[node(g, i, j, k)], before[node(g, i + 2, j - 1, k)]);
    // A jump far away: the whole grid starts again at body temperature.
    g.advanceUnheated(Vec3(1, 1, 1), 0.0);
    EXPECT_EQ(g.maxTemperature(), 37.0);
    EXPECT_EQ(g.minTemperature(), 37.0);
}

TEST(HeatGrid, TrilinearInterpolationAndTheSphere) {
    HeatGrid g(smallGrid());
    const double dl = 0.5e-3;
    EXPECT_EQ(g.temperatureAt(Vec3::Zero()), 37.0); // before the first advance
    const Vec3 c(0.2e-3, 0.1e-3, 0);
    g.advance({c, 0.8e-3, 150}, 0.03);
    const Vec3 o = g.origin();
    const auto& u = g.values();
    // At a node: the node value; at a cell centre: the mean of its 8 nodes.
    EXPECT_NEAR(g.temperatureAt(o + dl * Vec3(2, 3, 4)), u[node(g, 2, 3, 4)], 1e-12);
    double mean = 0;
    for (int dz = 0; dz < 2; ++dz)
        for (int dy = 0; dy < 2; ++dy)
            for (int dx = 0; dx < 2; ++dx)
                mean += u[node(g, 2 + dx, 3 + dy, 4 + dz)] / 8.0;
    EXPECT_NEAR(g.temperatureAt(o + dl * Vec3(2.5, 3.5, 4.5)), mean, 1e-12);
    // Along x between two nodes (outside the sphere): linear.
    const double a = u[node(g, 7, 5, 5)], b = u[node(g, 8, 5, 5)];
    ASSERT_GT((o + dl * Vec3(7, 5, 5) - c).norm(), 0.8e-3);
    EXPECT_GT(a, b); // warmer towards the tool
    EXPECT_NEAR(g.temperatureAt(o + dl * Vec3(7.25, 5, 5)), 0.75 * a + 0.25 * b, 1e-12);
    // Inside the sphere: the tool temperature; outside the grid: the body temperature.
    EXPECT_EQ(g.temperatureAt(c + Vec3(0.5e-3, 0, 0)), 150.0);
    EXPECT_EQ(g.temperatureAt(c + Vec3(0.1, 0, 0)), 37.0);
}

TEST(HeatGrid, BadInputNamesTheField) {
    HeatGridSettings s;
    s.nodes = 2;
    try {
        HeatGrid g(s);
        FAIL();
    } catch (const std::invalid_argument& e) {
        EXPECT_THAT(e.what(), HasSubstr("sim::HeatGrid: nodes is 2 (must be 4..256)"));
    }
    s = {};
    s.diffusivity = -1;
    EXPECT_THROW(HeatGrid{s}, std::invalid_argument);
    HeatGrid g(HeatGridSettings{});
    EXPECT_THROW(g.advance({Vec3(NAN, 0, 0), 1e-3, 170}, 0.01), std::invalid_argument);
    EXPECT_THROW(g.advance({Vec3::Zero(), 0.0, 170}, 0.01), std::invalid_argument);
    EXPECT_THROW(g.advance({Vec3::Zero(), 1e-3, -300}, 0.01), std::invalid_argument);
    EXPECT_THROW(g.advance({Vec3::Zero(), 1e-3, 170}, -1), std::invalid_argument);
    EXPECT_FALSE(g.placed()); // nothing changed
}
