// Multi-layer tissue [A §4.2]: fascia membranes, couplings, embedded tissue, surface strain
// limits in the UV frame, and the XpbdSystem that solves them together.
#include "sim/diagnostics/stability_check.hpp"
#include "sim/material/stable_neo_hookean.hpp"
#include "sim/xpbd/coupling.hpp"
#include "sim/xpbd/membrane.hpp"
#include "sim/xpbd/xpbd_system.hpp"
#include "xpbd_test_support.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>

using namespace viscera::sim;
using namespace viscera::sim::testing;
using ::testing::HasSubstr;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// A (nu × nv)-cell triangulated sheet origin + s·du + t·dv, s, t ∈ [0, 1]; uv = (s |du|, t |dv|).
TriMesh sheet(const Vec3& origin, const Vec3& du, const Vec3& dv, int nu, int nv, std::vector<Vec2>* uv = nullptr) {
    std::vector<Vec3> x;
    std::vector<Tri> tris;
    for (int j = 0; j <= nv; ++j)
        for (int i = 0; i <= nu; ++i) {
            const double s = double(i) / nu, t = double(j) / nv;
            x.push_back(origin + s * du + t * dv);
            if (uv) uv->push_back(Vec2(s * du.norm(), t * dv.norm()));
        }
    auto id = [&](int i, int j) { return j * (nu + 1) + i; };
    for (int j = 0; j < nv; ++j)
        for (int i = 0; i < nu; ++i) {
            tris.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
            tris.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
        }
    return TriMesh::fromArrays(std::move(x), std::move(tris));
}

std::shared_ptr<const TetConstraintModel> snh(double E, double nu = 0.45) {
    const Material m = tissue(E, nu);
    return std::make_shared<StableNeoHookeanModel>(m.mu(), m.lambda());
}

/// Fat: a 6 × 2 × 2 cm cantilever fixed at x = 0; fascia on its top face (a finer, independent
/// triangulation); a vessel: a 4 × 0.8 × 0.8 cm tet bar inside it.
///
/// Element sizes and stiffnesses keep h² (λ + 2μ)/(ρ L²) below 1 for the stable Neo-Hookean
/// bodies (see xpbd_solver.hpp: its two-constraint split is only stable there).
struct Layers {
    std::unique_ptr<TetMesh> fat = makeBoxTetMesh({Vec3::Zero(), Vec3(0.06, 0.02, 0.02), {12, 4, 4}});
    std::unique_ptr<TetMesh> vessel = makeBoxTetMesh({Vec3(0.01, 0.006, 0.006), Vec3(0.04, 0.008, 0.008), {8, 1, 1}});
    std::vector<Vec2> uv; // filled by the fascia initialiser below (declared first)
    TriMesh fascia = sheet(Vec3(0, 0, 0.02), Vec3(0.06, 0, 0), Vec3(0, 0.02, 0), 15, 5, &uv);
    std::vector<int32_t> fatFixed;

    Layers() {
        for (int32_t v = 0; v < static_cast<int32_t>(fat->vertexCount()); ++v)
            if (fat->positions()[v].x() < 1e-9) fatFixed.push_back(v);
    }

    XpbdSystemDesc desc(double fatE = 3000, double vesselE = 10000, double fasciaK = 50) const {
        XpbdSystemDesc d;
        TetBodyDesc f;
        f.name = "fat";
        f.mesh = fat.get();
        f.model = snh(fatE);
        f.density = 950;
        f.fixedNodes = fatFixed;
        TetBodyDesc v;
        v.name = "vessel";
        v.mesh = vessel.get();
        v.model = snh(vesselE);
        v.density = 1050;
        d.tetBodies = {f, v};
        SurfaceBodyDesc s;
        s.name = "fascia";
        s.mesh = &fascia;
        s.uv = uv;
        s.stretchStiffness = fasciaK;
        d.surfaces = {s};
        d.attachments.push_back({0, 0, 1e-4, 0.0, true});
        d.embeddings.push_back({1, 0, 0.0, 1e-9});
        return d;
    }
};

double maxSag(const std::vector<Vec3>& rest, const std::vector<Vec3>& x) {
    double s = 0;
    for (size_t i = 0; i < x.size(); ++i)
        s = std::max(s, rest[i].z() - x[i].z());
    return s;
}

} // namespace

TEST(Membrane, ConstraintGradientsMatchFiniteDifferences) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-1, 1);
    double worst = 0;
    for (int trial = 0; trial < 40; ++trial) {
        std::vector<Vec3> X = {Vec3::Zero(), Vec3(0.01, 0, 0), Vec3(0.002, 0.01, 0)};
        for (Vec3& p : X)
            p += 0.002 * Vec3(u(rng), u(rng), u(rng));
        Mat2 M;
        ASSERT_TRUE(triangleRestDmInv({X[0], X[1], X[2]}, M));
        // Rest: zero strain.
        for (double c : membraneConstraints({X[0], X[1], X[2]}, M))
            EXPECT_NEAR(c, 0.0, 1e-13);
        const Mat3 F = randomF(rng, 0.4);
        std::vector<Vec3> x(3);
        for (int k = 0; k < 3; ++k)
            x[k] = F * X[k] + 1e-3 * Vec3(u(rng), u(rng), u(rng));
        std::array<std::array<Vec3, 3>, 3> g;
        membraneConstraints({x[0], x[1], x[2]}, M, &g);
        for (int c = 0; c < 3; ++c) {
            const auto f = [&](const std::vector<Vec3>& y) { return membraneConstraints({y[0], y[1], y[2]}, M)[c]; };
            worst = std::max(worst, fdRelativeError(f, x, {g[c].begin(), g[c].end()}));
        }
    }
    EXPECT_LT(worst, 1e-6);
}

TEST(Coupling, ResidualGradientMatchesFiniteDifferences) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-1, 1);
    double worst = 0;
    for (int n : {3, 4})
        for (int trial = 0; trial < 10; ++trial) {
            std::vector<Vec3> x(n + 1);
            for (Vec3& p : x)
                p = 0.01 * Vec3(u(rng), u(rng), u(rng));
            double b[4];
            double sum = 0;
            for (int k = 0; k < n; ++k)
                sum += (b[k] = 0.1 + std::abs(u(rng)));
            for (int k = 0; k < n; ++k)
                b[k] /= sum;
            for (int c = 0; c < 3; ++c) {
                // ∂C_c/∂x_p = e_c, ∂C_c/∂x_k = −b_k e_c.
                std::vector<Vec3> g(n + 1, Vec3::Zero());
                g[0][c] = 1;
                for (int k = 0; k < n; ++k)
                    g[k + 1][c] = -b[k];
                const auto f = [&](const std::vector<Vec3>& y) {
                    return couplingResidual(y[0], y.data() + 1, b, n)[c];
                };
                worst = std::max(worst, fdRelativeError(f, x, g));
            }
        }
    EXPECT_LT(worst, 1e-6);
}

TEST(Coupling, ClosestPointOnTriangleMatchesDenseSampling) {
    std::mt19937 rng(9);
    std::uniform_real_distribution<double> u(-1, 1);
    const Vec3 a(0, 0, 0), b(1, 0.1, 0), c(0.2, 0.9, 0.1);
    for (int trial = 0; trial < 200; ++trial) {
        const Vec3 p = 1.5 * Vec3(u(rng), u(rng), u(rng));
        Eigen::Vector3d bary;
        const Vec3 q = closestPointOnTriangle(p, a, b, c, bary);
        EXPECT_NEAR(bary.sum(), 1.0, 1e-12);
        EXPECT_GE(bary.minCoeff(), -1e-12);
        EXPECT_LT((bary[0] * a + bary[1] * b + bary[2] * c - q).norm(), 1e-12);
        double best = kInf;
        const int n = 200;
        for (int i = 0; i <= n; ++i)
            for (int j = 0; i + j <= n; ++j) {
                const double s = double(i) / n, t = double(j) / n;
                best = std::min(best, (a + s * (b - a) + t * (c - a) - p).norm());
            }
        EXPECT_LE((q - p).norm(), best + 1e-12);
        EXPECT_GE((q - p).norm(), best - 0.01);
    }
}

TEST(Coupling, BoundaryProjectionAndCageLocation) {
    auto box = makeBoxTetMesh({Vec3::Zero(), Vec3(0.02, 0.02, 0.02), {3, 3, 3}});
    std::mt19937 rng(13);
    std::uniform_real_distribution<double> u(0.001, 0.019);
    std::vector<Vec3> above, inside;
    for (int i = 0; i < 50; ++i) {
        above.push_back(Vec3(u(rng), u(rng), 0.0205));
        inside.push_back(Vec3(u(rng), u(rng), u(rng)));
    }
    inside.push_back(Vec3(0.01, 0.01, 0.01)); // centre (far from the boundary)
    const auto proj = projectOntoBoundary(*box, above, 1e-3);
    ASSERT_EQ(proj.size(), above.size());
    for (const BoundaryProjection& p : proj) {
        Vec3 q = Vec3::Zero();
        for (int k = 0; k < 3; ++k)
            q += p.bary[k] * box->positions()[p.vertices[k]];
        EXPECT_LT((q - Vec3(above[p.point].x(), above[p.point].y(), 0.02)).norm(), 1e-12);
        EXPECT_NEAR(p.distance, 5e-4, 1e-12);
    }
    EXPECT_EQ(projectOntoBoundary(*box, {Vec3(0.01, 0.01, 0.01)}, 1e-3).size(), 0u);

    const auto loc = locateInCage(*box, inside, 1e-9);
    ASSERT_EQ(loc.size(), inside.size());
    for (const CageLocation& c : loc) {
        Vec3 q = Vec3::Zero();
        for (int k = 0; k < 4; ++k)
            q += c.bary[k] * box->positions()[box->tets()[c.tet][k]];
        EXPECT_LT((q - inside[c.point]).norm(), 1e-13);
        EXPECT_GE(c.bary.minCoeff(), -1e-12);
    }
    try {
        locateInCage(*box, {Vec3(0.01, 0.01, 0.01), Vec3(0.01, 0.01, 0.03)}, 1e-3);
        ADD_FAILURE() << "a point outside the cage was accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_THAT(e.what(), HasSubstr("sim::locateInCage(): point 1 lies more than 0.001"));
    }
}

TEST(XpbdSystem, RestStateIsAFixedPoint) {
    Layers L;
    XpbdSettings s;
    s.gravity.setZero();
    auto sys = XpbdSystem::create(L.desc(), s);
    EXPECT_EQ(sys->tetBodyCount(), 2u);
    EXPECT_EQ(sys->surfaceCount(), 1u);
    EXPECT_EQ(sys->tieCount(), L.fascia.vertexCount() + L.vessel->vertexCount());
    EXPECT_LT(sys->maxTieGap(), 1e-15);
    for (int f = 0; f < 10; ++f)
        EXPECT_LT(sys->step().maxDisplacement, 1e-15);
    EXPECT_NEAR(sys->elasticEnergy(), 0.0, 1e-15);
}

TEST(XpbdSystem, FasciaAndVesselFollowTheFat) {
    Layers L;
    XpbdSettings s;
    s.substeps = 20;
    s.damping = 2.0;
    auto sys = XpbdSystem::create(L.desc(), s);
    double worstGap = 0;
    for (int f = 0; f < 180; ++f) {
        ASSERT_TRUE(sys->step().finite);
        worstGap = std::max(worstGap, sys->maxTieGap());
    }
    // Hard ties, one iteration per substep: the layers stay together to a small fraction of a
    // millimetre while the cantilever sags by centimetres.
    const double fatSag = maxSag(L.fat->positions(), sys->tetPositions(0));
    EXPECT_GT(fatSag, 0.01);
    EXPECT_LT(worstGap, 2e-4);
    EXPECT_LT(sys->maxTieGap(), 5e-5);
    EXPECT_GT(maxSag(L.fascia.positions(), sys->surfacePositions(0)), 0.8 * fatSag);
    EXPECT_GT(maxSag(L.vessel->positions(), sys->tetPositions(1)), 0.3 * fatSag);
    EXPECT_LT(sys->kineticEnergy(), 1e-5);
}

TEST(XpbdSystem, CompliantTiesLetTheLayersSlideApartElastically) {
    Layers L;
    XpbdSettings s;
    s.substeps = 20;
    s.damping = 2.0;
    XpbdSystemDesc d = L.desc();
    d.attachments[0].compliance = 1e-2; // m/N: soft
    d.embeddings[0].compliance = 1e-2;
    auto soft = XpbdSystem::create(d, s);
    auto hard = XpbdSystem::create(L.desc(), s);
    for (int f = 0; f < 120; ++f) {
        soft->step();
        hard->step();
    }
    EXPECT_GT(soft->maxTieGap(), 5 * hard->maxTieGap());
    EXPECT_LT(soft->maxTieGap(), 0.01);
    EXPECT_GT(soft->elasticEnergy(), 0.0);
}

TEST(XpbdSystem, TiedInertiaSharesTheCageMassAmongTheEmbeddedNodes) {
    Layers L;
    auto sys = XpbdSystem::create(L.desc(), XpbdSettings{});
    const std::vector<double> vessel = sys->tiedInertia(1);
    ASSERT_EQ(vessel.size(), L.vessel->vertexCount());
    // Independently: lumped fat masses, the cage locations, the weight sums B_k, then
    // 1 / Σ_k b_k B_k / m_k per vessel node.
    std::vector<double> m(L.fat->vertexCount(), 0.0), B(m.size(), 0.0);
    double fatMass = 0;
    for (size_t t = 0; t < L.fat->tetCount(); ++t)
        for (int32_t v : L.fat->tets()[t]) {
            m[v] += 950 * L.fat->signedVolume(t) / 4;
            fatMass += 950 * L.fat->signedVolume(t) / 4;
        }
    const auto loc = locateInCage(*L.fat, L.vessel->positions(), 1e-9);
    for (const CageLocation& c : loc)
        for (int k = 0; k < 4; ++k)
            B[L.fat->tets()[c.tet][k]] += std::max(c.bary[k], 0.0);
    double sum = 0;
    for (const CageLocation& c : loc) {
        double inv = 0;
        for (int k = 0; k < 4; ++k) {
            const int32_t n = L.fat->tets()[c.tet][k];
            if (c.bary[k] > 0) inv += c.bary[k] * B[n] / m[n];
        }
        EXPECT_NEAR(vessel[c.point], 1 / inv, 1e-12 / inv) << "node " << c.point;
        EXPECT_GT(vessel[c.point], 0.0);
        sum += vessel[c.point];
    }
    EXPECT_LE(sum, fatMass) << "no cage mass counts twice";
    // Nothing is tied to the fat's own nodes (the fascia's ties move fascia vertices).
    for (double a : sys->tiedInertia(0))
        EXPECT_EQ(a, 0.0);
    // Compliant ties add nothing; a cage held in place makes the tied nodes immovable.
    XpbdSystemDesc soft = L.desc();
    soft.embeddings[0].compliance = 1e-6;
    for (double a : XpbdSystem::create(soft, XpbdSettings{})->tiedInertia(1))
        EXPECT_EQ(a, 0.0);
    XpbdSystemDesc held = L.desc();
    held.tetBodies[0].fixedNodes.resize(L.fat->vertexCount());
    for (int32_t v = 0; v < static_cast<int32_t>(L.fat->vertexCount()); ++v)
        held.tetBodies[0].fixedNodes[v] = v;
    for (double a : XpbdSystem::create(held, XpbdSettings{})->tiedInertia(1))
        EXPECT_EQ(a, kInf);
    EXPECT_THROW(sys->tiedInertia(2), std::out_of_range);
}

TEST(StabilityCheck, TiedMassDividesTheStiffnessNumber) {
    Layers L;
    const auto model = snh(10000);
    XpbdSettings s;
    s.substeps = 20;
    const StabilityFigures alone = assessStability(*L.vessel, *model, 1050, {}, s);
    const StabilityFigures zero =
        assessStability(*L.vessel, *model, 1050, {}, s, std::vector<double>(L.vessel->vertexCount(), 0.0));
    EXPECT_EQ(zero.maxStiffnessNumber, alone.maxStiffnessNumber);
    EXPECT_EQ(zero.worstTet, alone.worstTet);
    // Three times each node's own lumped mass tied to it: every tet moves 4 times the inertia.
    std::vector<double> own(L.vessel->vertexCount(), 0.0);
    for (size_t t = 0; t < L.vessel->tetCount(); ++t)
        for (int32_t v : L.vessel->tets()[t])
            own[v] += 1050 * L.vessel->signedVolume(t) / 4;
    for (double& m : own)
        m *= 3;
    const StabilityFigures tied = assessStability(*L.vessel, *model, 1050, {}, s, own);
    EXPECT_NEAR(tied.maxStiffnessNumber, alone.maxStiffnessNumber / 4, 1e-12 * alone.maxStiffnessNumber);
    // Immovable nodes (+inf) make their tets' number 0.
    const StabilityFigures held =
        assessStability(*L.vessel, *model, 1050, {}, s, std::vector<double>(L.vessel->vertexCount(), kInf));
    EXPECT_EQ(held.maxStiffnessNumber, 0.0);
    EXPECT_TRUE(held.ok());
    try {
        assessStability(*L.vessel, *model, 1050, {}, s, {1.0});
        ADD_FAILURE() << "a tiedMass of the wrong size was accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_THAT(e.what(), HasSubstr("sim::assessStability(): tiedMass has 1 values for"));
    }
}

TEST(XpbdSystem, StiffnessRatioOfAMillionStaysFiniteAndBounded) {
    Layers L;
    XpbdSettings s;
    s.substeps = 20;
    s.damping = 2.0;
    // Fat 1 kPa; vessel 1 GPa (10^6 times stiffer); fascia k 10^6 times the fat's E · thickness.
    // The stiff layers use constraints without rest pretension (one C = sqrt(2Ψ) per tet, a
    // Green-strain membrane): far beyond h² k/m ~ 1, where the stable Neo-Hookean split is not
    // stable (see xpbd_solver.hpp), XPBD then behaves like PBD, as stiff as its iterations allow.
    XpbdSystemDesc d = L.desc(1e3, 1e4, 1e3 * 0.02 * 1e6);
    const Material vessel = tissue(1e9);
    d.tetBodies[1].model = std::make_shared<OneConstraintStvkModel>(vessel.mu(), vessel.lambda());
    auto sys = XpbdSystem::create(d, s);
    std::vector<double> elastic;
    double drop = 0;
    for (int f = 0; f < 240; ++f) {
        const StepStats st = sys->step();
        ASSERT_TRUE(st.finite) << "frame " << f;
        ASSERT_EQ(st.speedClamps, 0) << "frame " << f;
        ASSERT_LT(st.maxDisplacement, 0.03) << "frame " << f;
        elastic.push_back(sys->elasticEnergy());
        ASSERT_TRUE(std::isfinite(elastic.back()));
        drop = std::max(drop, -sys->potentialEnergy());
    }
    // Everything stays near the 6 cm cantilever it hangs from, and comes to rest.
    auto inBox = [](const std::vector<Vec3>& x) {
        for (const Vec3& p : x)
            if (!p.allFinite() || p.x() < -0.05 || p.x() > 0.11 || std::abs(p.y() - 0.01) > 0.06 || p.z() < -0.1 ||
                p.z() > 0.07)
                return false;
        return true;
    };
    EXPECT_TRUE(inBox(sys->tetPositions(0)));
    EXPECT_TRUE(inBox(sys->tetPositions(1)));
    EXPECT_TRUE(inBox(sys->surfacePositions(0)));
    EXPECT_LT(sys->kineticEnergy(), 1e-2 * drop);
    EXPECT_LT(sys->maxTieGap(), 5e-4);
    // No growth: the stored energy (large: the stiff layers are as stiff as one iteration per
    // substep makes them, and the hard ties have the last word) peaks early and then decays.
    const double early = *std::max_element(elastic.begin(), elastic.begin() + 120);
    const double late = *std::max_element(elastic.begin() + 120, elastic.end());
    EXPECT_LE(late, early);
}

TEST(XpbdSystem, SurfaceStrainLimitsInTheUvFrame) {
    // A 4 × 4 cm sheet hanging from its top edge; u runs down the sheet, v across.
    std::vector<Vec2> uv;
    TriMesh mesh = sheet(Vec3(0, 0, 0.04), Vec3(0, 0, -0.04), Vec3(0.04, 0, 0), 8, 8, &uv);
    SurfaceBodyDesc s;
    s.name = "membrane";
    s.mesh = &mesh;
    s.uv = uv;
    s.stretchStiffness = 0.5; // N/m: very soft, stretches a lot under its own weight
    s.arealDensity = 0.2;
    for (int32_t v = 0; v < static_cast<int32_t>(mesh.vertexCount()); ++v)
        if (mesh.positions()[v].z() > 0.04 - 1e-9) s.fixedNodes.push_back(v);
    XpbdSettings set;
    set.substeps = 20;
    set.iterations = 10;
    set.damping = 5;
    auto run = [&](std::optional<TriStrainLimits> limits) {
        XpbdSystemDesc d;
        SurfaceBodyDesc body = s;
        body.strainLimits = std::move(limits);
        d.surfaces = {body};
        auto sys = XpbdSystem::create(d, set);
        for (int f = 0; f < 120; ++f)
            EXPECT_TRUE(sys->step().finite);
        return sys->surfacePositions(0);
    };
    auto range = [&](const std::vector<Vec3>& x, int i, int j) {
        double lo = kInf, hi = -kInf;
        for (const Tri& t : mesh.triangles()) {
            Mat2 M;
            triangleUvDmInv({mesh.positions()[t[0]], mesh.positions()[t[1]], mesh.positions()[t[2]]},
                            {uv[t[0]], uv[t[1]], uv[t[2]]}, M);
            const double e = triGreenStrain({x[t[0]], x[t[1]], x[t[2]]}, M, i, j);
            lo = std::min(lo, e);
            hi = std::max(hi, e);
        }
        return std::make_pair(lo, hi);
    };
    const auto free = run(std::nullopt);
    EXPECT_GT(range(free, 0, 0).second, 0.1);
    TriStrainLimits along;
    along.limits.push_back({0, 0, -kInf, 0.02, 0.0});
    const auto u = run(along);
    EXPECT_LE(range(u, 0, 0).second, 0.02 + 2e-3);
    TriStrainLimits both = along;
    both.limits.push_back({1, 1, -0.01, 0.01, 0.0});
    const auto uvLimited = run(both);
    EXPECT_LE(range(uvLimited, 0, 0).second, 0.02 + 2e-3);
    const auto across = range(uvLimited, 1, 1);
    EXPECT_GE(across.first, -0.01 - 2e-3);
    EXPECT_LE(across.second, 0.01 + 2e-3);
}

TEST(XpbdSystem, PaintedFasciaWeightsScaleEachTrianglesStiffness) {
    // [A Fig. 4.11] polygon paint: a triangle's k is stretchStiffness × the mean of its vertices'
    // weights. Checked on the stored energy of one stretched state (exact per triangle), then on
    // the settled stretch of a hanging sheet painted stiff on one half.
    std::vector<Vec2> uv;
    TriMesh mesh = sheet(Vec3(0, 0, 0.04), Vec3(0, 0, -0.04), Vec3(0.04, 0, 0), 8, 8, &uv);
    const size_t nv = mesh.vertexCount();
    SurfaceBodyDesc s;
    s.name = "membrane";
    s.mesh = &mesh;
    s.uv = uv;
    s.stretchStiffness = 0.5;
    s.arealDensity = 0.2;
    for (int32_t v = 0; v < static_cast<int32_t>(nv); ++v)
        if (mesh.positions()[v].z() > 0.04 - 1e-9) s.fixedNodes.push_back(v);
    auto energyOf = [&](const std::vector<double>& w, size_t onlyTri = SIZE_MAX) {
        XpbdSystemDesc d;
        SurfaceBodyDesc body = s;
        body.nodeWeights = w;
        TriMesh one;
        if (onlyTri != SIZE_MAX) { // the triangle alone, unweighted
            const Tri& t = mesh.triangles()[onlyTri];
            one = TriMesh::fromArrays({mesh.positions()[t[0]], mesh.positions()[t[1]], mesh.positions()[t[2]]},
                                      {Tri{0, 1, 2}});
            body.mesh = &one;
            body.uv = {uv[t[0]], uv[t[1]], uv[t[2]]};
            body.fixedNodes.clear();
        }
        d.surfaces = {body};
        auto sys = XpbdSystem::create(d, XpbdSettings{});
        std::vector<Vec3> x = body.mesh->positions();
        for (Vec3& p : x)
            p = Vec3(1.3 * p.x(), p.y() + 0.2 * p.x(), 0.9 * p.z() + 0.1 * p.x() * p.x() / 0.04);
        sys->setSurfaceState(0, x, std::vector<Vec3>(x.size(), Vec3::Zero()));
        return sys->elasticEnergy();
    };
    std::vector<double> w(nv);
    for (size_t i = 0; i < nv; ++i)
        w[i] = 0.5 + 3.0 * std::abs(std::sin(1.3 * double(i)));
    const double painted = energyOf(w);
    long double expected = 0;
    for (size_t t = 0; t < mesh.triangleCount(); ++t) {
        const Tri& tri = mesh.triangles()[t];
        expected += (w[tri[0]] + w[tri[1]] + w[tri[2]]) / 3.0L * energyOf({}, t);
    }
    EXPECT_GT(painted, 0.0);
    EXPECT_NEAR(painted, static_cast<double>(expected), 1e-12 * painted) << "sum of k_t · E_t";
    EXPECT_NEAR(energyOf(std::vector<double>(nv, 4.0)), 4.0 * energyOf({}), 1e-12 * energyOf({}));

    // hanging: the half at x > 2 cm painted 5× stretches less than the other half
    auto hang = [&](const std::vector<double>& weights) {
        XpbdSystemDesc d;
        SurfaceBodyDesc body = s;
        body.nodeWeights = weights;
        d.surfaces = {body};
        XpbdSettings set;
        set.substeps = 20;
        set.iterations = 10;
        set.damping = 5;
        auto sys = XpbdSystem::create(d, set);
        for (int f = 0; f < 120; ++f)
            EXPECT_TRUE(sys->step().finite);
        return sys->surfacePositions(0);
    };
    std::vector<double> half(nv, 1.0);
    for (size_t i = 0; i < nv; ++i)
        if (mesh.positions()[i].x() > 0.02 + 1e-9) half[i] = 5.0;
    const auto plain = hang({}), stiff = hang(half);
    auto drop = [&](const std::vector<Vec3>& x, bool right) { // mean fall of a half's vertices
        double sum = 0;
        int n = 0;
        for (size_t i = 0; i < nv; ++i)
            if ((mesh.positions()[i].x() > 0.02 + 1e-9) == right && mesh.positions()[i].x() != 0.02) {
                sum += mesh.positions()[i].z() - x[i].z();
                ++n;
            }
        return sum / n;
    };
    EXPECT_GT(drop(plain, true), 1e-3) << "m: the soft sheet stretches under its weight";
    EXPECT_LT(drop(stiff, true), 0.6 * drop(plain, true)) << "the painted half stretches less";
    EXPECT_LT(drop(stiff, true) / drop(stiff, false), 0.8 * drop(plain, true) / drop(plain, false));
    // bad weights are refused with the layer named
    try {
        std::vector<double> bad(nv, 1.0);
        bad[5] = -1.0;
        energyOf(bad);
        ADD_FAILURE() << "a negative weight was accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_THAT(e.what(), HasSubstr("membrane"));
        EXPECT_THAT(e.what(), HasSubstr("node weight 5 is -1"));
    }
    EXPECT_THROW(energyOf(std::vector<double>(3, 1.0)), std::invalid_argument);
}

namespace {

/// Fat 20 × 10 × 10 cm fixed at x = 0, a strain-limited vessel embedded in it, fascia tied on
/// top: large enough that colours and particle passes are split between threads.
struct BigLayers {
    std::unique_ptr<TetMesh> fat = makeBoxTetMesh({Vec3::Zero(), Vec3(0.2, 0.1, 0.1), {20, 10, 10}});
    std::unique_ptr<TetMesh> vessel = makeBoxTetMesh({Vec3(0.02, 0.04, 0.04), Vec3(0.16, 0.02, 0.02), {16, 2, 2}});
    TriMesh fascia = sheet(Vec3(0, 0, 0.1), Vec3(0.2, 0, 0), Vec3(0, 0.1, 0), 40, 20);
    XpbdSystemDesc desc;

    BigLayers() {
        std::vector<int32_t> fixed;
        for (int32_t v = 0; v < static_cast<int32_t>(fat->vertexCount()); ++v)
            if (fat->positions()[v].x() < 1e-9) fixed.push_back(v);
        desc.tetBodies.push_back({"fat", fat.get(), snh(3000), 950, fixed, {}, {}});
        TetStrainLimits limits;
        limits.limits.push_back({0, 0, -kInf, 0.05, 0.0});
        desc.tetBodies.push_back({"vessel", vessel.get(), snh(30000), 100, {}, {}, limits});
        SurfaceBodyDesc s;
        s.name = "fascia";
        s.mesh = &fascia;
        desc.surfaces.push_back(s);
        desc.attachments.push_back({0, 0, 1e-4, 0.0, true});
        desc.embeddings.push_back({1, 0, 0.0, 1e-9});
    }
};

std::vector<Vec3> allPositions(const XpbdSystem& sys) {
    std::vector<Vec3> all = sys.tetPositions(0);
    all.insert(all.end(), sys.tetPositions(1).begin(), sys.tetPositions(1).end());
    all.insert(all.end(), sys.surfacePositions(0).begin(), sys.surfacePositions(0).end());
    return all;
}

} // namespace

// Frames and the stored energy (summed in parallel parts) are the same to the bit for any number
// of threads.
TEST(XpbdSystem, BitIdenticalAcrossThreadCounts) {
    const BigLayers L;
    std::vector<std::vector<Vec3>> results;
    std::vector<double> energies;
    for (int threads : {1, 2, 3}) {
        XpbdSettings set;
        set.substeps = 5;
        set.threads = threads;
        auto sys = XpbdSystem::create(L.desc, set);
        for (int f = 0; f < 3; ++f)
            ASSERT_TRUE(sys->step().finite);
        results.push_back(allPositions(*sys));
        energies.push_back(sys->elasticEnergy()); // summed in parallel parts
    }
    EXPECT_EQ(results[1], results[0]);
    EXPECT_EQ(results[2], results[0]);
    EXPECT_GT(energies[0], 0);
    EXPECT_EQ(energies[1], energies[0]);
    EXPECT_EQ(energies[2], energies[0]);
}

// A hook that declares the particles it touches (the fascia: a tool pressing on it during the
// sweeps and damping its contact velocities in the velocity pass) ends each substep beside the other
// particles' pass instead of after it: the frames are bit-identical to the same hook without the
// declaration, for one to three threads and one or two iterations. A hook switched off for a
// frame is not called and the frame is the one without a hook.
TEST(XpbdSystem, HookOnItsOwnParticlesGivesTheFramesOfTheHookOnAll) {
    const BigLayers L;
    for (int iterations : {1, 2}) {
        std::vector<std::vector<Vec3>> results;
        std::vector<long> calls;
        for (int threads : {1, 2, 3})
            for (bool declared : {false, true}) {
                SCOPED_TRACE(::testing::Message() << iterations << " iterations, " << threads << " threads, "
                                                  << (declared ? "declared" : "all particles"));
                XpbdSettings set;
                set.substeps = 5;
                set.iterations = iterations;
                set.threads = threads;
                auto sys = XpbdSystem::create(L.desc, set);
                const size_t first = sys->surfaceParticleOffset(0), count = sys->surfacePositions(0).size();
                long n = 0;
                sys->setIterationHook([&, first, count](XpbdParticles& p, const XpbdIterationInfo& info) {
                    ++n;
                    for (size_t i = first; i < first + count; ++i) {
                        Vec3 x = p.position(i);
                        if (info.velocityPass) {
                            if (x.x() > 0.15) p.setVelocity(i, 0.5 * p.velocity(i)); // contact friction
                        } else if (x.x() > 0.15 && x.z() > 0.0995) {
                            x.z() = 0.0995; // a flat tool 0.5 mm into the fascia's free end
                            p.setPosition(i, x);
                        }
                    }
                });
                if (declared) sys->setIterationHookParticles(first, count);
                for (int f = 0; f < 4; ++f)
                    ASSERT_TRUE(sys->step().finite);
                results.push_back(allPositions(*sys));
                calls.push_back(n);
            }
        for (size_t k = 1; k < results.size(); ++k) {
            EXPECT_EQ(results[k], results[0]) << "run " << k;
            EXPECT_EQ(calls[k], calls[0]);
        }
        EXPECT_EQ(calls[0], 4 * 5 * (iterations + 1)); // every sweep and every velocity pass
    }
    XpbdSettings set;
    set.substeps = 5;
    set.threads = 2;
    auto plain = XpbdSystem::create(L.desc, set);
    auto off = XpbdSystem::create(L.desc, set);
    long n = 0;
    off->setIterationHook([&](XpbdParticles&, const XpbdIterationInfo&) { ++n; });
    off->setIterationHookActive(false);
    for (int f = 0; f < 3; ++f) {
        ASSERT_TRUE(plain->step().finite);
        ASSERT_TRUE(off->step().finite);
    }
    EXPECT_EQ(n, 0);
    EXPECT_EQ(allPositions(*off), allPositions(*plain));
    off->setIterationHookActive(true);
    ASSERT_TRUE(off->step().finite);
    EXPECT_EQ(n, 5 * 2);
}

TEST(XpbdSystem, MembraneSimdAndScalarKernelsAgree) {
    // The fascia's AVX2 kernel against the scalar path: same equations, the last bits differ
    // (fused multiply-adds). A hard kick, a cut and a shrunk triangle exercise the packs' lane
    // masks and rest shapes; values stay finite and the energy bounded; SIMD runs repeat bit for bit.
    Layers L;
    auto run = [&](bool simd) {
        XpbdSettings s;
        s.substeps = 10;
        s.simd = simd;
        XpbdSystemDesc d = L.desc();
        // painted: every triangle its own k, so the packs' per-lane stiffness is checked too
        d.surfaces[0].nodeWeights.resize(L.fascia.vertexCount());
        for (size_t i = 0; i < L.fascia.vertexCount(); ++i)
            d.surfaces[0].nodeWeights[i] = 1.0 + std::abs(std::cos(0.7 * double(i)));
        auto sys = XpbdSystem::create(d, s);
        std::vector<Vec3> v(L.fascia.vertexCount(), Vec3::Zero());
        for (size_t i = 0; i < v.size(); ++i)
            v[i] = Vec3(0.3 * std::sin(1.7 * double(i)), 0.3 * std::cos(2.3 * double(i)), 0.5);
        sys->setSurfaceState(0, sys->surfacePositions(0), v);
        sys->setTriangleActive(0, 7, false);
        Mat3 shrink = Mat3::Identity() * 0.8;
        sys->setTriangleRestShape(0, 20, shrink);
        // Bounded: the stored energy of one sweep per substep (the embedded vessel fights the fat)
        // exceeds the work of gravity here, so the check is that it does not grow: the last ten
        // frames stay below the largest of the first twenty.
        double early = 0, late = 0;
        for (int f = 0; f < 30; ++f) {
            EXPECT_TRUE(sys->step().finite);
            const double e = sys->elasticEnergy() + sys->kineticEnergy() + sys->potentialEnergy();
            EXPECT_TRUE(std::isfinite(e));
            (f < 20 ? early : late) = std::max(f < 20 ? early : late, e);
        }
        EXPECT_LT(late, early);
        const double maxEnergy = std::max(early, late);
        return std::make_pair(sys->surfacePositions(0), maxEnergy);
    };
    {
        XpbdSettings s;
        if (!XpbdSystem::create(L.desc(), s)->usesSimd()) GTEST_SKIP() << "no AVX2/FMA on this CPU";
    }
    const auto [simd, eSimd] = run(true);
    const auto [scalar, eScalar] = run(false);
    double diff = 0;
    for (size_t i = 0; i < simd.size(); ++i) {
        ASSERT_TRUE(simd[i].allFinite());
        diff = std::max(diff, (simd[i] - scalar[i]).norm());
    }
    EXPECT_LT(diff, 1e-9) << "m, after 30 frames";
    EXPECT_NEAR(eSimd, eScalar, 1e-9 * eScalar);
    EXPECT_EQ(run(true).first, simd) << "repeat runs must be bit-identical";
}

TEST(XpbdSystem, AddedInertiaKeepsTheWeightAndSlowsTheFall) {
    // A free block with every node's inertia tripled falls at g / 3 (its weight m g moves 3 m),
    // the kinetic energy counts the scaled inertia; zeros restore the plain fall bit for bit.
    auto block = makeBoxTetMesh({Vec3::Zero(), Vec3(0.02, 0.02, 0.02), {2, 2, 2}});
    XpbdSystemDesc d;
    d.tetBodies.push_back({"block", block.get(), snh(3000), 1000, {}, {}, {}});
    XpbdSettings s;
    s.substeps = 4;
    s.damping = 0;
    auto plain = XpbdSystem::create(d, s), scaled = XpbdSystem::create(d, s), restored = XpbdSystem::create(d, s);
    std::vector<double> own(block->vertexCount(), 0.0);
    for (const Tet& t : block->tets())
        for (int32_t v : t)
            own[v] += 1000 * std::abs(block->signedVolume(&t - block->tets().data())) / 4;
    std::vector<double> twice = own;
    for (double& m : twice)
        m *= 2;
    scaled->setAddedInertia(0, twice);
    EXPECT_EQ(scaled->addedInertia(0), twice);
    restored->setAddedInertia(0, twice);
    restored->setAddedInertia(0, std::vector<double>(own.size(), 0.0));
    for (int f = 0; f < 3; ++f) {
        plain->step();
        scaled->step();
        restored->step();
    }
    const double vp = plain->tetVelocities(0)[0].z(), vs = scaled->tetVelocities(0)[0].z();
    EXPECT_NEAR(vp, -9.81 * 3 * s.dt, 1e-9);
    EXPECT_NEAR(vs, vp / 3, 1e-9);
    EXPECT_NEAR(scaled->kineticEnergy(), plain->kineticEnergy() / 3, 1e-9 * plain->kineticEnergy());
    EXPECT_EQ(restored->tetPositions(0), plain->tetPositions(0));
    try {
        scaled->setAddedInertia(0, {1.0});
        ADD_FAILURE() << "accepted a short vector";
    } catch (const std::invalid_argument& e) {
        EXPECT_THAT(e.what(), HasSubstr("sim::XpbdSystem::setAddedInertia(): expected"));
    }
    twice[3] = -1;
    EXPECT_THROW(scaled->setAddedInertia(0, twice), std::invalid_argument);
}

TEST(StabilityCheck, StabilizingInertiaBringsEveryTetUnderTheLimitWithinItsCap) {
    auto block = makeBoxTetMesh({Vec3::Zero(), Vec3(0.04, 0.01, 0.01), {8, 2, 2}});
    const auto model = snh(200000);
    XpbdSettings s;
    s.substeps = 2;
    const StabilityFigures before = assessStability(*block, *model, 1000, {}, s);
    ASSERT_FALSE(before.ok());
    const auto none = stabilizingInertia(*block, *model, 1000, {}, s, {}, 1.0);
    EXPECT_EQ(*std::max_element(none.begin(), none.end()), 0.0) << "a cap of 1 adds nothing";
    const double need = before.maxStiffnessNumber;
    const auto extra = stabilizingInertia(*block, *model, 1000, {}, s, {}, need * 1.01);
    EXPECT_TRUE(assessStability(*block, *model, 1000, {}, s, extra).ok());
    const auto capped = stabilizingInertia(*block, *model, 1000, {}, s, {}, 0.5 * need);
    EXPECT_FALSE(assessStability(*block, *model, 1000, {}, s, capped).ok());
    s.substeps = before.requiredSubsteps;
    const auto at = stabilizingInertia(*block, *model, 1000, {}, s, {}, 4);
    EXPECT_EQ(*std::max_element(at.begin(), at.end()), 0.0) << "nothing over the limit, nothing added";
}

TEST(XpbdSystem, RejectsInvalidCouplings) {
    Layers L;
    XpbdSettings s;
    auto msg = [&](const XpbdSystemDesc& d) {
        try {
            XpbdSystem::create(d, s);
        } catch (const std::invalid_argument& e) {
            return std::string(e.what());
        }
        return std::string("accepted");
    };
    XpbdSystemDesc d = L.desc();
    d.attachments[0].maxDistance = 0;
    TriMesh far = sheet(Vec3(0, 0, 0.05), Vec3(0.06, 0, 0), Vec3(0, 0.02, 0), 3, 3);
    d.surfaces[0].mesh = &far;
    d.surfaces[0].uv.clear();
    EXPECT_THAT(msg(d), HasSubstr("sim::XpbdSystem::create(): attachment 0: no vertex of surface "
                                  "'fascia' lies within 0 m"));
    d = L.desc();
    auto outside = makeBoxTetMesh({Vec3(0.05, 0.0, 0.0), Vec3(0.04, 0.01, 0.01), {2, 1, 1}});
    d.tetBodies[1].mesh = outside.get();
    EXPECT_THAT(msg(d), HasSubstr("embedding 0: 'vessel' in 'fat': node"));
    EXPECT_THAT(msg(d), HasSubstr("outside the cage"));
    d = L.desc();
    d.surfaces[0].uv.clear();
    d.surfaces[0].strainLimits = TriStrainLimits{{{0, 0, -kInf, 0.1, 0.0}}, {}};
    EXPECT_THAT(msg(d), HasSubstr("surface 0 ('fascia'): strain limits need per-vertex uv coordinates"));
    d = L.desc();
    d.embeddings[0].cage = 1;
    EXPECT_THAT(msg(d), HasSubstr("cannot be embedded in itself"));
    d = L.desc();
    d.tetBodies[0].fixedNodes.push_back(100000);
    EXPECT_THAT(msg(d), HasSubstr("tet body 0 ('fat'): fixed node 100000 is out of range"));
}
