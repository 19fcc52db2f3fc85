#include "sim/mesh/generators.hpp"
#include "sim/xpbd/xpbd_solver.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

using namespace viscera::sim;
using ::testing::HasSubstr;

namespace {

struct Cantilever {
    std::unique_ptr<TetMesh> mesh;
    std::vector<int32_t> fixed;
};

Cantilever cantilever(std::array<int, 3> cells = {8, 2, 2}) {
    Cantilever c;
    c.mesh = makeBoxTetMesh({Vec3::Zero(), Vec3(0.08, 0.02, 0.02), cells});
    for (int32_t v = 0; v < static_cast<int32_t>(c.mesh->vertexCount()); ++v)
        if (c.mesh->positions()[v].x() < 1e-9) c.fixed.push_back(v);
    return c;
}

Material tissue(double E = 20000, double nu = 0.45) {
    Material m;
    m.youngsModulus = E;
    m.poissonRatio = nu;
    return m;
}

} // namespace

TEST(XpbdSolver, RestStateStaysAtRestWithoutLoad) {
    auto c = cantilever();
    XpbdSettings s;
    s.gravity.setZero();
    auto solver = XpbdSolver::create(*c.mesh, tissue(), c.fixed, s);
    for (int f = 0; f < 30; ++f) {
        StepStats st = solver->step();
        ASSERT_TRUE(st.finite);
        EXPECT_LT(st.maxDisplacement, 1e-12);
    }
    EXPECT_NEAR(solver->elasticEnergy(), 0.0, 1e-12);
}

TEST(XpbdSolver, CantileverSagsFiniteBoundedAndDeterministic) {
    auto c = cantilever();
    XpbdSettings s;
    s.substeps = 20;
    s.damping = 2.0;
    auto a = XpbdSolver::create(*c.mesh, tissue(), c.fixed, s);
    auto b = XpbdSolver::create(*c.mesh, tissue(), c.fixed, s);
    double maxEnergy = -1e300, maxPotentialDrop = 0;
    for (int f = 0; f < 240; ++f) {
        StepStats sa = a->step(), sb = b->step();
        ASSERT_TRUE(sa.finite);
        const double e = a->elasticEnergy() + a->kineticEnergy() + a->potentialEnergy();
        ASSERT_TRUE(std::isfinite(e));
        maxEnergy = std::max(maxEnergy, e);
        maxPotentialDrop = std::max(maxPotentialDrop, -a->potentialEnergy());
        // Capped per-frame motion: well below the slab length.
        EXPECT_LT(sa.maxDisplacement, 0.02);
        ASSERT_EQ(sa.maxDisplacement, sb.maxDisplacement);
    }
    // Bit-identical repeat runs.
    EXPECT_EQ(a->positions(), b->positions());
    // A damped system starting at rest gains no energy beyond the splitting error of one XPBD
    // iteration per substep (measured: about 2% of the gravitational work during the first fall).
    EXPECT_LE(maxEnergy, 0.05 * maxPotentialDrop);
    // Fixed nodes stay put; the free end sags by millimetres.
    for (int32_t v : c.fixed) EXPECT_EQ(a->positions()[v], c.mesh->positions()[v]);
    double tip = 0;
    for (size_t v = 0; v < a->positions().size(); ++v)
        tip = std::max(tip, c.mesh->positions()[v].z() - a->positions()[v].z());
    // 20 kPa tissue, 8 cm long and 2 cm thick: a large, finite sag (linear beam theory, which
    // overestimates at this size, gives 8 cm).
    EXPECT_GT(tip, 0.01);
    EXPECT_LT(tip, 0.08);
    // At rest after settling.
    EXPECT_LT(a->kineticEnergy(), 1e-6);
}

TEST(XpbdSolver, StifferMaterialSagsLess) {
    auto c = cantilever();
    XpbdSettings s;
    s.substeps = 20;
    s.damping = 2.0;
    auto soft = XpbdSolver::create(*c.mesh, tissue(10000), c.fixed, s);
    auto stiff = XpbdSolver::create(*c.mesh, tissue(40000), c.fixed, s);
    for (int f = 0; f < 240; ++f) {
        soft->step();
        stiff->step();
    }
    auto sag = [&](const XpbdSolver& x) {
        double m = 0;
        for (size_t v = 0; v < x.positions().size(); ++v)
            m = std::max(m, c.mesh->positions()[v].z() - x.positions()[v].z());
        return m;
    };
    EXPECT_GT(sag(*soft), 1.5 * sag(*stiff));
}

TEST(XpbdSolver, RefusesAnInvertedRestState) {
    auto c = cantilever({4, 2, 2});
    XpbdSettings s;
    s.gravity.setZero();
    s.substeps = 20;
    s.damping = 5.0;
    auto solver = XpbdSolver::create(*c.mesh, tissue(), c.fixed, s);
    // A mirrored copy has every element inverted; it cannot serve as a rest state.
    std::vector<Vec3> mirrored = c.mesh->positions();
    for (Vec3& p : mirrored) p.z() = 0.02 - p.z();
    auto inv = TetMesh::fromArrays(mirrored, c.mesh->tets());
    EXPECT_FALSE(inv->quality().inverted.empty());
    EXPECT_THROW(XpbdSolver::create(*inv, tissue(), c.fixed, s), std::invalid_argument)
        << "an inverted rest state is refused at load";
}

TEST(XpbdSolver, RejectsUnstableParametersAtCreation) {
    auto c = cantilever();
    XpbdSettings s;
    auto msg = [&](const Material& m, const XpbdSettings& st, std::vector<int32_t> fixed) {
        try {
            XpbdSolver::create(*c.mesh, m, fixed, st);
        } catch (const std::invalid_argument& e) {
            return std::string(e.what());
        }
        return std::string("accepted");
    };
    EXPECT_THAT(msg(tissue(20000, 0.5), s, c.fixed), HasSubstr("poisson_ratio"));
    EXPECT_THAT(msg(tissue(-1), s, c.fixed), HasSubstr("youngs_modulus"));
    XpbdSettings bad = s;
    bad.dt = 0;
    EXPECT_THAT(msg(tissue(), bad, c.fixed), HasSubstr("dt must be in (0, 0.1] s"));
    bad = s;
    bad.substeps = 0;
    EXPECT_THAT(msg(tissue(), bad, c.fixed), HasSubstr("substeps"));
    EXPECT_THAT(msg(tissue(), s, {999999}), HasSubstr("fixed node 999999 is out of range"));
    std::vector<int32_t> all(c.mesh->vertexCount());
    for (size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int32_t>(i);
    EXPECT_THAT(msg(tissue(), s, all), HasSubstr("no free node"));
}

TEST(XpbdSolver, HugeTimeStepAndNearIncompressibleStayFinite) {
    auto c = cantilever();
    XpbdSettings s;
    s.dt = 0.1; // 6x the nominal frame
    s.substeps = 2;
    auto solver = XpbdSolver::create(*c.mesh, tissue(1e6, 0.499), c.fixed, s);
    for (int f = 0; f < 50; ++f) {
        StepStats st = solver->step();
        ASSERT_TRUE(st.finite);
        for (const Vec3& p : solver->positions()) ASSERT_TRUE(p.allFinite());
        for (const Vec3& v : solver->velocities()) ASSERT_LE(v.norm(), s.maxSpeed * (1 + 1e-12));
    }
}
