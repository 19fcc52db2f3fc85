#include "sim/material/stable_neo_hookean.hpp"
#include "sim/mesh/generators.hpp"
#include "sim/xpbd/xpbd_solver.hpp"
#include "xpbd_test_support.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <limits>

using namespace viscera::sim;
using ::testing::HasSubstr;

using namespace viscera::sim::testing;

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
    for (int32_t v : c.fixed)
        EXPECT_EQ(a->positions()[v], c.mesh->positions()[v]);
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
    for (Vec3& p : mirrored)
        p.z() = 0.02 - p.z();
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
    for (size_t i = 0; i < all.size(); ++i)
        all[i] = static_cast<int32_t>(i);
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
        for (const Vec3& p : solver->positions())
            ASSERT_TRUE(p.allFinite());
        for (const Vec3& v : solver->velocities())
            ASSERT_LE(v.norm(), s.maxSpeed * (1 + 1e-12));
    }
}

TEST(XpbdSolver, GenericModelPathMatchesTheStableNeoHookeanFastPath) {
    auto c = cantilever();
    XpbdSettings s;
    s.substeps = 20;
    s.simd = false; // compare the two scalar paths
    const Material m = tissue();
    auto fast = XpbdSolver::create(*c.mesh, m, c.fixed, s);
    TetBodyDesc body;
    body.mesh = c.mesh.get();
    body.model = std::make_shared<GenericSnhModel>(m.mu(), m.lambda());
    body.density = m.density;
    body.fixedNodes = c.fixed;
    auto generic = XpbdSolver::create(body, s);
    EXPECT_EQ(generic->model().name(), "test_generic_snh");
    for (int f = 0; f < 30; ++f) {
        ASSERT_TRUE(fast->step().finite);
        ASSERT_TRUE(generic->step().finite);
    }
    // Same equations, differently arranged: agreement to rounding, far below the 1e-2 m sag.
    double diff = 0;
    for (size_t v = 0; v < fast->positions().size(); ++v)
        diff = std::max(diff, (fast->positions()[v] - generic->positions()[v]).norm());
    EXPECT_LT(diff, 1e-9);
    EXPECT_NEAR(fast->elasticEnergy(), generic->elasticEnergy(), 1e-9 * std::abs(fast->elasticEnergy()));
}

TEST(XpbdSolver, OneConstraintModelRestsAndSags) {
    auto c = cantilever();
    const Material m = tissue();
    TetBodyDesc body;
    body.mesh = c.mesh.get();
    body.model = std::make_shared<OneConstraintStvkModel>(m.mu(), m.lambda());
    body.fixedNodes = c.fixed;
    XpbdSettings s;
    s.substeps = 20;
    s.damping = 2.0;
    s.gravity.setZero();
    auto rest = XpbdSolver::create(body, s);
    for (int f = 0; f < 10; ++f)
        EXPECT_EQ(rest->step().maxDisplacement, 0.0);
    EXPECT_EQ(rest->elasticEnergy(), 0.0);
    s.gravity = Vec3(0, 0, -9.81);
    auto sag = XpbdSolver::create(body, s);
    for (int f = 0; f < 240; ++f)
        ASSERT_TRUE(sag->step().finite);
    double tip = 0;
    for (size_t v = 0; v < sag->positions().size(); ++v)
        tip = std::max(tip, c.mesh->positions()[v].z() - sag->positions()[v].z());
    EXPECT_GT(tip, 0.005);
    EXPECT_LT(tip, 0.08);
    EXPECT_LT(sag->kineticEnergy(), 1e-5);
}

TEST(XpbdSolver, NodeWeightsScaleTheStiffness) {
    auto c = cantilever();
    const Material m = tissue();
    TetBodyDesc body;
    body.mesh = c.mesh.get();
    body.model = std::make_shared<StableNeoHookeanModel>(m.mu(), m.lambda());
    body.fixedNodes = c.fixed;
    XpbdSettings s;
    s.substeps = 20;
    s.damping = 2.0;
    auto plain = XpbdSolver::create(body, s);
    for (double w : plain->tetWeights())
        EXPECT_EQ(w, 1.0);
    body.nodeWeights.assign(c.mesh->vertexCount(), 1.0);
    body.nodeWeights[c.mesh->tets()[0][0]] = 5.0; // tet weight = mean of its nodes
    auto painted = XpbdSolver::create(body, s);
    EXPECT_DOUBLE_EQ(painted->tetWeights()[0], 2.0);
    body.nodeWeights.assign(c.mesh->vertexCount(), 4.0);
    auto stiff = XpbdSolver::create(body, s);
    for (int f = 0; f < 240; ++f) {
        plain->step();
        stiff->step();
    }
    auto sag = [&](const XpbdSolver& x) {
        double d = 0;
        for (size_t v = 0; v < x.positions().size(); ++v)
            d = std::max(d, c.mesh->positions()[v].z() - x.positions()[v].z());
        return d;
    };
    EXPECT_GT(sag(*plain), 2.0 * sag(*stiff));
    body.nodeWeights.assign(3, 1.0);
    EXPECT_THROW(XpbdSolver::create(body, s), std::invalid_argument);
    body.nodeWeights.assign(c.mesh->vertexCount(), 1.0);
    body.nodeWeights[7] = 0.0;
    try {
        XpbdSolver::create(body, s);
        ADD_FAILURE() << "a zero weight was accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_THAT(e.what(), HasSubstr("node weight 7 is 0"));
    }
}

TEST(XpbdSolver, BitIdenticalAcrossRunsAndThreadCounts) {
    // Large enough that every colour is split between threads.
    auto mesh = makeBoxTetMesh({Vec3::Zero(), Vec3(0.2, 0.1, 0.1), {20, 10, 10}});
    std::vector<int32_t> fixed;
    for (int32_t v = 0; v < static_cast<int32_t>(mesh->vertexCount()); ++v)
        if (mesh->positions()[v].x() < 1e-9) fixed.push_back(v);
    for (int variant = 0; variant < 3; ++variant) {
        const bool simd = variant != 1, primal = variant == 2;
        std::vector<std::vector<Vec3>> results;
        std::vector<double> energies;
        for (int threads : {1, 2, 3, 4, 2}) {
            XpbdSettings s;
            s.substeps = primal ? 20 : 5;
            s.iterations = 2;
            s.threads = threads;
            s.simd = simd;
            s.primalCorrection = primal;
            auto solver = XpbdSolver::create(*mesh, tissue(), fixed, s);
            EXPECT_GT(solver->colourCount(), 1);
            for (int f = 0; f < 4; ++f)
                ASSERT_TRUE(solver->step().finite);
            results.push_back(solver->positions());
            energies.push_back(solver->elasticEnergy());
        }
        for (size_t k = 1; k < results.size(); ++k) {
            EXPECT_EQ(results[k], results[0]) << "simd " << simd << ", primal correction " << primal << ", run " << k;
            EXPECT_EQ(energies[k], energies[0]);
        }
    }
}

TEST(XpbdSolver, SimdAndScalarKernelsAgree) {
    auto c = cantilever();
    XpbdSettings s;
    s.substeps = 20;
    auto simd = XpbdSolver::create(*c.mesh, tissue(), c.fixed, s);
    if (!simd->usesSimd()) GTEST_SKIP() << "no AVX2/FMA on this CPU";
    s.simd = false;
    auto scalar = XpbdSolver::create(*c.mesh, tissue(), c.fixed, s);
    EXPECT_FALSE(scalar->usesSimd());
    for (int f = 0; f < 30; ++f) {
        simd->step();
        scalar->step();
    }
    double diff = 0;
    for (size_t v = 0; v < simd->positions().size(); ++v)
        diff = std::max(diff, (simd->positions()[v] - scalar->positions()[v]).norm());
    EXPECT_LT(diff, 1e-9);
}

namespace {
/// A broken model whose constraint turns NaN once the tet is stretched: drives a frame
/// non-finite.
class PoisonModel final : public TetConstraintModel {
public:
    std::string name() const override { return "test_poison"; }
    int count() const override { return 1; }
    std::array<double, kMaxTetConstraints> compliance() const override { return {1e-3, 1e-3}; }
    void evaluate(const Mat3& F, TetConstraintValues& out) const override {
        out.count = 1;
        const bool stretched = F.norm() > std::sqrt(3.0) * (1 + 1e-6);
        out.C[0] = stretched ? std::numeric_limits<double>::quiet_NaN() : 0.0;
        out.dCdF[0] = stretched ? Mat3(Mat3::Identity()) : Mat3(Mat3::Zero());
    }
    double restStiffness() const override { return 1e3; }
};
} // namespace

TEST(XpbdSolver, NonFiniteFrameIsRolledBack) {
    auto c = cantilever({4, 2, 2});
    TetBodyDesc body;
    body.mesh = c.mesh.get();
    body.model = std::make_shared<PoisonModel>();
    body.fixedNodes = c.fixed;
    XpbdSettings s;
    auto solver = XpbdSolver::create(body, s);
    bool rolledBack = false;
    for (int f = 0; f < 20 && !rolledBack; ++f) {
        const std::vector<Vec3> before = solver->positions(), vBefore = solver->velocities();
        const StepStats st = solver->step();
        if (!st.finite) {
            rolledBack = true;
            EXPECT_EQ(solver->positions(), before);
            EXPECT_EQ(solver->velocities(), vBefore);
            EXPECT_EQ(st.maxDisplacement, 0.0);
        }
        for (const Vec3& p : solver->positions())
            ASSERT_TRUE(p.allFinite());
    }
    EXPECT_TRUE(rolledBack);
}

TEST(XpbdSolver, SetStateTeleportsAndValidates) {
    auto c = cantilever({4, 2, 2});
    XpbdSettings s;
    s.gravity.setZero();
    auto solver = XpbdSolver::create(*c.mesh, tissue(), c.fixed, s);
    std::vector<Vec3> x = c.mesh->positions();
    for (Vec3& p : x)
        p += Vec3(0.1, 0, 0); // a rigid translation stays at rest
    solver->setState(x, std::vector<Vec3>(x.size(), Vec3::Zero()));
    EXPECT_EQ(solver->positions(), x);
    EXPECT_LT(solver->step().maxDisplacement, 1e-12);
    try {
        solver->setState({Vec3::Zero()}, {Vec3::Zero()});
        ADD_FAILURE() << "size mismatch accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_THAT(e.what(), HasSubstr("sim::XpbdSolver::setState(): expected"));
    }
    x[3].x() = std::numeric_limits<double>::quiet_NaN();
    EXPECT_THROW(solver->setState(x, std::vector<Vec3>(x.size(), Vec3::Zero())), std::invalid_argument);
}

TEST(XpbdSolver, RejectsUnsupportedModelsAndSettings) {
    auto c = cantilever({4, 2, 2});
    TetBodyDesc body;
    body.mesh = c.mesh.get();
    body.fixedNodes = c.fixed;
    XpbdSettings s;
    auto msg = [&](const TetBodyDesc& b, const XpbdSettings& st) {
        try {
            XpbdSolver::create(b, st);
        } catch (const std::invalid_argument& e) {
            return std::string(e.what());
        }
        return std::string("accepted");
    };
    EXPECT_THAT(msg(body, s), HasSubstr("sim::XpbdSolver::create(): constraint model is null"));
    body.model = std::make_shared<StableNeoHookeanModel>(1e3, 1e4);
    XpbdSettings bad = s;
    bad.threads = 0;
    EXPECT_THAT(msg(body, bad), HasSubstr("threads must be in [1, 64]"));
    body.density = 0;
    EXPECT_THAT(msg(body, s), HasSubstr("density must be positive"));
    body.density = 1000;
    body.mesh = nullptr;
    EXPECT_THAT(msg(body, s), HasSubstr("mesh is null"));
}

// The stored energy of a body large enough to be summed in several parts (12,000 tets, threads
// 1 and 2) under a uniform deformation F is V Ψ(F), Ψ the stable Neo-Hookean density relative
// to rest: μ/2 (|F|² − 3) + λ/2 ((J − γ)² − (1 − γ)²), γ = 1 + μ/λ.
TEST(XpbdSolver, EnergyOfAUniformDeformationIsVolumeTimesDensity) {
    auto mesh = makeBoxTetMesh({Vec3::Zero(), Vec3(0.2, 0.1, 0.1), {20, 10, 10}});
    const Material m = tissue(5000, 0.45);
    Mat3 F;
    F << 1.10, 0.05, 0.00, //
        0.02, 0.95, 0.03,  //
        0.00, -0.04, 1.02;
    const double mu = m.mu(), la = m.lambda(), g = 1 + mu / la, J = F.determinant();
    const double psi = 0.5 * mu * (F.squaredNorm() - 3) + 0.5 * la * ((J - g) * (J - g) - (1 - g) * (1 - g));
    std::vector<Vec3> x;
    for (const Vec3& p : mesh->positions())
        x.push_back(F * p);
    for (int threads : {1, 2}) {
        XpbdSettings s;
        s.threads = threads;
        auto solver = XpbdSolver::create(*mesh, m, {}, s);
        solver->setState(x, std::vector<Vec3>(x.size(), Vec3::Zero()));
        EXPECT_NEAR(solver->elasticEnergy(), 0.2 * 0.1 * 0.1 * psi, 1e-9 * std::abs(psi)) << threads << " threads";
    }
}
