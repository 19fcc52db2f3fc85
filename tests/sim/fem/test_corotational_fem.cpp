#include "sim/fem/corotational_fem.hpp"
#include "sim/mesh/generators.hpp"

#include <gtest/gtest.h>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseLU>

#include <random>

using namespace viscera::sim;

namespace {

struct Bar {
    std::unique_ptr<TetMesh> mesh;
    std::vector<int32_t> fixed;
    std::vector<Vec3> gravity;
};

Bar makeBar(std::array<int, 3> cells = {6, 2, 2}) {
    Bar b;
    b.mesh = makeBoxTetMesh({Vec3::Zero(), Vec3(0.06, 0.02, 0.02), cells});
    const auto& p = b.mesh->positions();
    b.gravity.assign(p.size(), Vec3(0, 0, -1e-3)); // N per node
    for (int32_t v = 0; v < static_cast<int32_t>(p.size()); ++v)
        if (p[v].x() < 1e-9) b.fixed.push_back(v);
    return b;
}

double maxAbs(const Eigen::VectorXd& v) {
    return v.size() ? v.cwiseAbs().maxCoeff() : 0.0;
}

Eigen::VectorXd displacement(const CorotationalFem& fem) {
    Eigen::VectorXd u(3 * fem.nodeCount());
    for (size_t v = 0; v < fem.nodeCount(); ++v)
        u.segment<3>(3 * v) = fem.positions()[v] - fem.restPositions()[v];
    return u;
}

/// Point constraint: the material point with barycentric coordinates w in tet t goes to target.
ConstraintDesc pointConstraint(const TetMesh& m, int t, const Eigen::Vector4d& w, const Vec3& target,
                               int priority = 0) {
    ConstraintDesc d;
    d.priority = priority;
    for (int k = 0; k < 3; ++k) {
        ConstraintRow r;
        for (int a = 0; a < 4; ++a)
            r.terms.push_back({m.tets()[t][a], w[a] * Vec3::Unit(k)});
        r.b = target[k];
        d.rows.push_back(r);
    }
    return d;
}

Vec3 materialPoint(const CorotationalFem& fem, const TetMesh& m, int t, const Eigen::Vector4d& w) {
    Vec3 p = Vec3::Zero();
    for (int a = 0; a < 4; ++a)
        p += w[a] * fem.positions()[m.tets()[t][a]];
    return p;
}

/// Full KKT [K Cᵀ; C 0] solved with a sparse LU: the reference of the Schur-complement path.
void fullKkt(const Eigen::SparseMatrix<double>& K, const Eigen::VectorXd& f, const Eigen::MatrixXd& C,
             const Eigen::VectorXd& b, Eigen::VectorXd& u, Eigen::VectorXd& lambda) {
    const int n = static_cast<int>(K.rows()), m = static_cast<int>(C.rows());
    std::vector<Eigen::Triplet<double>> t;
    for (int k = 0; k < K.outerSize(); ++k)
        for (Eigen::SparseMatrix<double>::InnerIterator it(K, k); it; ++it)
            t.emplace_back(it.row(), it.col(), it.value());
    for (int r = 0; r < m; ++r)
        for (int c = 0; c < n; ++c)
            if (C(r, c) != 0) {
                t.emplace_back(n + r, c, C(r, c));
                t.emplace_back(c, n + r, C(r, c));
            }
    Eigen::SparseMatrix<double> A(n + m, n + m);
    A.setFromTriplets(t.begin(), t.end());
    Eigen::VectorXd rhs(n + m);
    rhs << f, b;
    Eigen::SparseLU<Eigen::SparseMatrix<double>> lu;
    lu.compute(A);
    ASSERT_EQ(lu.info(), Eigen::Success);
    const Eigen::VectorXd x = lu.solve(rhs);
    u = x.head(n);
    lambda = x.tail(m);
}

FemSettings linearSettings() {
    FemSettings s;
    s.corotational = false;
    s.refactorMode = RefactorMode::Synchronous;
    return s;
}

} // namespace

TEST(CorotationalFem, UnconstrainedMatchesDirectSparseSolve) {
    for (bool corot : {false, true}) {
        Bar bar = makeBar({12, 4, 4});
        FemSettings s = linearSettings();
        s.corotational = corot;
        s.refactorDisplacement = 1e9; // rotations only where the test asks for them
        auto fem = CorotationalFem::create(*bar.mesh, bar.fixed, s, bar.gravity);
        if (corot) {
            // Bend the bar with a constraint, then take the rotations of the bent state.
            const int id = fem->addConstraint(pointConstraint(*bar.mesh, static_cast<int>(bar.mesh->tetCount()) - 1,
                                                              Eigen::Vector4d::Constant(0.25), Vec3(0.05, 0.03, 0.02)));
            ASSERT_TRUE(fem->solve().finite);
            ASSERT_TRUE(fem->refactorNow());
            fem->removeConstraint(id);
        }
        const FemSolveStats st = fem->solve();
        ASSERT_TRUE(st.finite) << st.error;
        Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(fem->stiffnessMatrix());
        ASSERT_EQ(ldlt.info(), Eigen::Success);
        const Eigen::VectorXd ref = ldlt.solve(fem->forceVector());
        const double err = maxAbs(displacement(*fem) - ref) / maxAbs(ref);
        RecordProperty(corot ? "corotational_rel_error" : "linear_rel_error", std::to_string(err));
        EXPECT_LT(err, 1e-10) << (corot ? "corotational" : "linear");
        EXPECT_GT(maxAbs(ref), 1e-6);
    }
}

TEST(CorotationalFem, ConstraintsMatchFullKktSolve) {
    Bar bar = makeBar({10, 3, 3});
    const TetMesh& m = *bar.mesh;
    for (bool corot : {false, true}) {
        FemSettings s = linearSettings();
        s.corotational = corot;
        s.refactorDisplacement = 1e9;
        auto fem = CorotationalFem::create(m, bar.fixed, s, bar.gravity);
        std::mt19937 rng(5);
        std::uniform_int_distribution<int> tet(0, static_cast<int>(m.tetCount()) - 1);
        std::uniform_real_distribution<double> u(0.05, 1.0), d(-1, 1);
        for (int k = 0; k < 6; ++k) {
            Eigen::Vector4d w(u(rng), u(rng), u(rng), u(rng));
            w /= w.sum();
            const int t = tet(rng);
            Vec3 rest = Vec3::Zero();
            for (int a = 0; a < 4; ++a)
                rest += w[a] * m.positions()[m.tets()[t][a]];
            fem->addConstraint(pointConstraint(m, t, w, rest + 2e-3 * Vec3(d(rng), d(rng), d(rng))));
        }
        for (int k = 0; k < 4; ++k) { // single rows along random directions (contact-like)
            ConstraintDesc c;
            ConstraintRow r;
            const Tet& T = m.tets()[tet(rng)];
            const Vec3 n = Vec3(d(rng), d(rng), d(rng)).normalized();
            r.terms = {{T[0], 0.5 * n}, {T[1], 0.5 * n}, {T[3], -n}};
            r.b = 0.5 * n.dot(m.positions()[T[0]] + m.positions()[T[1]]) - n.dot(m.positions()[T[3]]) + 1e-4;
            c.rows.push_back(r);
            fem->addConstraint(c);
        }
        FemSolveStats st = fem->solve();
        if (corot) { // once more with the rotations of the deformed state
            ASSERT_TRUE(fem->refactorNow());
            st = fem->solve();
        }
        ASSERT_TRUE(st.finite) << st.error;
        EXPECT_EQ(st.rows, 22);
        EXPECT_EQ(st.redundant + st.incompatible, 0);
        Eigen::MatrixXd C;
        Eigen::VectorXd b, lambda;
        fem->lastSystem(C, b, lambda);
        const Eigen::VectorXd uu = displacement(*fem);
        const double residual = maxAbs(C * uu - b);
        Eigen::VectorXd uRef, lRef;
        fullKkt(fem->stiffnessMatrix(), fem->forceVector(), C, b, uRef, lRef);
        const double uErr = maxAbs(uu - uRef) / maxAbs(uRef);
        const double lErr = maxAbs(lambda - lRef) / maxAbs(lRef);
        RecordProperty(corot ? "corot_cu_b_residual_m" : "linear_cu_b_residual_m", std::to_string(residual));
        RecordProperty(corot ? "corot_lambda_rel_error" : "linear_lambda_rel_error", std::to_string(lErr));
        EXPECT_LT(residual, 1e-9);
        EXPECT_LT(uErr, 1e-9);
        EXPECT_LT(lErr, 1e-9);
        // KKT stationarity: K u + Cᵀλ = f.
        EXPECT_LT(maxAbs(fem->stiffnessMatrix() * uu + C.transpose() * lambda - fem->forceVector()),
                  1e-9 * maxAbs(fem->forceVector().cwiseAbs() + (C.transpose() * lambda).cwiseAbs()));
    }
}

TEST(CorotationalFem, RedundantAndIncompatibleRowsAreRejected) {
    Bar bar = makeBar();
    const TetMesh& m = *bar.mesh;
    auto fem = CorotationalFem::create(m, bar.fixed, linearSettings(), bar.gravity);
    const Eigen::Vector4d w = Eigen::Vector4d::Constant(0.25);
    const int t = static_cast<int>(m.tetCount()) - 5;
    Vec3 rest = Vec3::Zero();
    for (int a = 0; a < 4; ++a)
        rest += 0.25 * m.positions()[m.tets()[t][a]];
    const Vec3 target = rest + Vec3(0, 0, 1e-3);
    const int a = fem->addConstraint(pointConstraint(m, t, w, target, 0));
    ASSERT_TRUE(fem->solve().finite);
    const std::vector<Vec3> alone = fem->positions();
    // The same point constraint again: redundant; with another target: incompatible.
    const int same = fem->addConstraint(pointConstraint(m, t, w, target, 1));
    FemSolveStats st = fem->solve();
    ASSERT_TRUE(st.finite);
    EXPECT_EQ(st.redundant, 3);
    EXPECT_EQ(st.incompatible, 0);
    EXPECT_EQ(fem->state(same).status[0], RowStatus::Redundant);
    const int clash = fem->addConstraint(pointConstraint(m, t, w, target + Vec3(1e-3, 0, 0), 2));
    st = fem->solve();
    ASSERT_TRUE(st.finite);
    EXPECT_EQ(st.incompatible, 1); // only x disagrees
    EXPECT_EQ(st.redundant, 5);
    EXPECT_EQ(fem->state(clash).status[0], RowStatus::Incompatible);
    for (size_t v = 0; v < alone.size(); ++v)
        EXPECT_LT((fem->positions()[v] - alone[v]).norm(), 1e-12);
    // A row on fixed nodes only is a zero row: rejected, never singular.
    ConstraintDesc z;
    z.rows.push_back({{{bar.fixed[0], Vec3(1, 0, 0)}}, 5.0});
    fem->addConstraint(z);
    st = fem->solve();
    EXPECT_TRUE(st.finite);
    EXPECT_EQ(st.incompatible, 2);
    EXPECT_NEAR((materialPoint(*fem, m, t, w) - target).norm(), 0, 1e-12);
    (void)a;
}

TEST(CorotationalFem, ConstraintsChangeWithoutRefactorization) {
    Bar bar = makeBar();
    const TetMesh& m = *bar.mesh;
    auto fem = CorotationalFem::create(m, bar.fixed, linearSettings(), bar.gravity);
    EXPECT_EQ(fem->factorizations(), 1);
    std::vector<int> ids;
    for (int k = 0; k < 20; ++k) {
        const int t = (k * 37) % static_cast<int>(m.tetCount());
        Vec3 rest = Vec3::Zero();
        for (int a = 0; a < 4; ++a)
            rest += 0.25 * m.positions()[m.tets()[t][a]];
        ids.push_back(
            fem->addConstraint(pointConstraint(m, t, Eigen::Vector4d::Constant(0.25), rest + Vec3(0, 0, 1e-4 * k))));
        const FemSolveStats st = fem->solve();
        ASSERT_TRUE(st.finite);
        if (k % 3 == 2) fem->removeConstraint(ids[k - 1]);
        fem->setRhs(ids[0], 2, rest.z() + 1e-5 * k); // moving target
    }
    EXPECT_EQ(fem->factorizations(), 1);
    const FemSolveStats st = fem->solve();
    EXPECT_EQ(st.newCachedNodes, 0); // every node's K⁻¹ block is cached
    EXPECT_EQ(st.substitutions, 0);  // u = u0 − Σ K⁻¹ columns · Cᵀλ: no substitution in a step
}

TEST(CorotationalFem, UnilateralGroupsReleaseAndActivate) {
    Bar bar = makeBar({8, 2, 2});
    const TetMesh& m = *bar.mesh;
    auto fem = CorotationalFem::create(m, bar.fixed, linearSettings(), bar.gravity);
    ASSERT_TRUE(fem->solve().finite);
    int tip = 0;
    for (int v = 0; v < static_cast<int>(m.vertexCount()); ++v)
        if (m.positions()[v].x() > m.positions()[tip].x() - 1e-12 && m.positions()[v].z() <= m.positions()[tip].z())
            tip = v;
    const double sag = m.positions()[tip].z() - fem->positions()[tip].z();
    ASSERT_GT(sag, 1e-6);
    // A floor half-way down the free sag: enforced, pushing (λ < 0 in K u + Cᵀλ = f).
    ConstraintDesc floor;
    floor.kind = ConstraintKind::Unilateral;
    floor.startActive = false;
    floor.rows.push_back({{{tip, Vec3(0, 0, 1)}}, m.positions()[tip].z() - 0.5 * sag});
    const int id = fem->addConstraint(floor);
    FemSolveStats st = fem->solve();
    ASSERT_TRUE(st.finite);
    EXPECT_TRUE(fem->state(id).active);
    EXPECT_LT(fem->state(id).lambda[0], 0);
    EXPECT_NEAR(fem->positions()[tip].z(), m.positions()[tip].z() - 0.5 * sag, 1e-12);
    // The floor far below, started active: it would pull, so it is released.
    fem->setRhs(id, 0, m.positions()[tip].z() - 1.0);
    st = fem->solve();
    EXPECT_FALSE(fem->state(id).active);
    EXPECT_NEAR(m.positions()[tip].z() - fem->positions()[tip].z(), sag, 1e-12);
}

TEST(CorotationalFem, BackgroundRefactorIsDeterministicAndOffThePath) {
    auto run = [](RefactorMode mode) {
        Bar bar = makeBar({10, 2, 2});
        FemSettings s;
        s.refactorMode = mode;
        s.refactorDisplacement = 0.05;
        auto fem = CorotationalFem::create(*bar.mesh, bar.fixed, s, bar.gravity);
        const int t = static_cast<int>(bar.mesh->tetCount()) - 1;
        Vec3 rest = Vec3::Zero();
        for (int a = 0; a < 4; ++a)
            rest += 0.25 * bar.mesh->positions()[bar.mesh->tets()[t][a]];
        const int id = fem->addConstraint(pointConstraint(*bar.mesh, t, Eigen::Vector4d::Constant(0.25), rest));
        std::vector<int> refactorSteps;
        for (int k = 0; k < 40; ++k) {
            for (int c = 0; c < 3; ++c)
                fem->setRhs(id, c, rest[c] + (c == 2 ? 1e-3 * k : 0.0));
            const FemSolveStats st = fem->solve();
            EXPECT_TRUE(st.finite);
            EXPECT_TRUE(st.error.empty()) << st.error;
            if (st.refactored) refactorSteps.push_back(k);
        }
        return std::make_pair(fem->positions(), refactorSteps);
    };
    const auto a = run(RefactorMode::Background), b = run(RefactorMode::Background);
    EXPECT_EQ(a.first, b.first); // bit-identical
    EXPECT_EQ(a.second, b.second);
    EXPECT_GE(a.second.size(), 2u);
    const auto c = run(RefactorMode::Synchronous);
    EXPECT_GE(c.second.size(), 2u);
}

TEST(CorotationalFem, NonFiniteRightHandSideIsDiscarded) {
    Bar bar = makeBar();
    auto fem = CorotationalFem::create(*bar.mesh, bar.fixed, linearSettings(), bar.gravity);
    ASSERT_TRUE(fem->solve().finite);
    const std::vector<Vec3> before = fem->positions();
    const int id = fem->addConstraint(pointConstraint(*bar.mesh, 3, Eigen::Vector4d::Constant(0.25), Vec3(0, 0, 0)));
    fem->setRhs(id, 1, std::numeric_limits<double>::quiet_NaN());
    const FemSolveStats st = fem->solve();
    EXPECT_FALSE(st.finite);
    EXPECT_FALSE(st.error.empty());
    EXPECT_EQ(fem->positions(), before);
}

TEST(CorotationalFem, CreateRejectsBadInputWithMessages) {
    Bar bar = makeBar();
    auto expectMessage = [](auto&& f, const char* text) {
        try {
            f();
            FAIL() << "expected invalid_argument";
        } catch (const std::invalid_argument& e) {
            EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
        }
    };
    FemSettings s;
    s.poissonRatio = 0.5;
    expectMessage([&] { CorotationalFem::create(*bar.mesh, bar.fixed, s); }, "poisson_ratio 0.5 must be in [0, 0.5)");
    expectMessage([&] { CorotationalFem::create(*bar.mesh, {99999}, FemSettings{}); },
                  "fixed node 99999 is out of range");
    expectMessage([&] { CorotationalFem::create(*bar.mesh, {}, FemSettings{}); }, "not positive definite");
}

namespace {

/// The bar's free end dragged by a point constraint along z by `step` per solve (large rotations).
struct Drag {
    Bar bar;
    int tet = 0;
    Vec3 rest = Vec3::Zero();
    explicit Drag() : bar(makeBar({10, 2, 2})) {
        tet = static_cast<int>(bar.mesh->tetCount()) - 1;
        for (int a = 0; a < 4; ++a)
            rest += 0.25 * bar.mesh->positions()[bar.mesh->tets()[tet][a]];
    }
    int constrain(CorotationalFem& fem) const {
        return fem.addConstraint(pointConstraint(*bar.mesh, tet, Eigen::Vector4d::Constant(0.25), rest));
    }
    void target(CorotationalFem& fem, int id, int k, double step = 1e-3) const {
        for (int c = 0; c < 3; ++c)
            fem.setRhs(id, c, rest[c] + (c == 2 ? step * k : 0.0));
    }
};

double maxDistance(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
    double d = 0;
    for (size_t v = 0; v < a.size(); ++v)
        d = std::max(d, (a[v] - b[v]).norm());
    return d;
}

} // namespace

TEST(CorotationalFem, BackgroundSwapEqualsASynchronousFactorizationOfTheSamePositions) {
    // Background: the worker factorizes the positions of the request; the carried columns are then
    // computed one node per solve; the swap comes at a fixed solve. A synchronous FEM that keeps its
    // factor and refactorizes at exactly that solve from the same positions must give the same result.
    const Drag d;
    FemSettings bs;
    bs.refactorMode = RefactorMode::Background;
    bs.refactorDisplacement = 0.05;
    bs.refactorLatencySteps = 4;
    bs.refactorNodesPerSolve = 1;
    auto a = CorotationalFem::create(*d.bar.mesh, d.bar.fixed, bs, d.bar.gravity);
    FemSettings ss = bs;
    ss.refactorMode = RefactorMode::Synchronous;
    ss.refactorDisplacement = 1e9; // refactorized by hand below
    auto b = CorotationalFem::create(*d.bar.mesh, d.bar.fixed, ss, d.bar.gravity);
    const int ia = d.constrain(*a), ib = d.constrain(*b);
    std::vector<Vec3> requestedAt;
    int started = -1, swaps = 0;
    for (int k = 0; k < 60; ++k) {
        d.target(*a, ia, k);
        d.target(*b, ib, k);
        const FemSolveStats sa = a->solve();
        ASSERT_TRUE(sa.finite && sa.error.empty()) << sa.error;
        if (sa.refactored) {
            // b had no solve with the new factor yet: refactorize from the request's positions and
            // redo this solve's problem.
            ASSERT_FALSE(requestedAt.empty());
            ASSERT_GT(k - started, bs.refactorLatencySteps); // the carried column takes at least one solve more
            std::string error;
            ASSERT_TRUE(b->refactorAt(requestedAt, &error)) << error;
            ++swaps;
        }
        const FemSolveStats sb = b->solve();
        ASSERT_TRUE(sb.finite);
        // Same factor on both sides at every solve: equal up to the rounding of the column batches.
        EXPECT_LT(maxDistance(a->positions(), b->positions()), 1e-12) << "solve " << k;
        if (sa.refactorStarted) {
            started = k;
            requestedAt = a->positions();
        }
    }
    EXPECT_GE(swaps, 2);
    EXPECT_EQ(a->factorizations(), b->factorizations());
}

TEST(CorotationalFem, PinnedNodesStayCachedAndPrefetchSpreadsTheSubstitutions) {
    const Drag d;
    FemSettings s;
    s.refactorMode = RefactorMode::Synchronous;
    s.refactorDisplacement = 1e9;
    s.cacheEvictSteps = 2;
    s.prefetchNodesPerSolve = 2;
    auto fem = CorotationalFem::create(*d.bar.mesh, d.bar.fixed, s, d.bar.gravity);
    auto plain = CorotationalFem::create(*d.bar.mesh, d.bar.fixed, s, d.bar.gravity);
    const int id = d.constrain(*fem), ip = d.constrain(*plain);
    ASSERT_TRUE(fem->solve().finite);
    ASSERT_TRUE(plain->solve().finite);
    const int constrained = fem->cachedNodes();
    EXPECT_EQ(constrained, 4);
    // Pin the constraint's nodes, then drop the constraint: they outlive the eviction age.
    const auto& t = d.bar.mesh->tets()[d.tet];
    fem->pinNodes({t[0], t[1], t[2], t[3]});
    fem->removeConstraint(id);
    plain->removeConstraint(ip);
    for (int k = 0; k < 6; ++k) {
        ASSERT_TRUE(fem->solve().finite);
        ASSERT_TRUE(plain->solve().finite);
    }
    EXPECT_EQ(fem->cachedNodes(), 4);
    EXPECT_EQ(plain->cachedNodes(), 0);
    // Prefetch: at most two queued nodes per solve, and the results do not change.
    const int32_t nv = static_cast<int32_t>(fem->nodeCount());
    std::vector<int32_t> ahead;
    for (int32_t v = nv - 1; static_cast<int>(ahead.size()) < 5; --v)
        if (!fem->isFixed(v) && std::find(t.begin(), t.end(), v) == t.end()) ahead.push_back(v);
    ahead.push_back(ahead[0]); // duplicates and fixed nodes are skipped
    ahead.push_back(d.bar.fixed[0]);
    fem->prefetchNodes(ahead);
    const FemSolveStats st = fem->solve();
    ASSERT_TRUE(plain->solve().finite);
    EXPECT_EQ(st.newCachedNodes, 2);
    EXPECT_EQ(st.substitutions, 6);
    EXPECT_EQ(fem->cachedNodes(), 6);
    for (int k = 0; k < 2; ++k)
        ASSERT_TRUE(fem->solve().finite);
    EXPECT_EQ(fem->cachedNodes(), 4 + 5); // not evicted yet (unused for two solves at most)
    EXPECT_LT(maxDistance(fem->positions(), plain->positions()), 1e-15);
}

TEST(CorotationalFem, ConvergedStaticReferenceIsTheFixedPointOfRefactorizing) {
    // Refactorizing at every solve with the constraint held still converges to the minimizer of the
    // corotational energy under that constraint; the reference reaches it by Newton from anywhere on
    // the way. The linear FEM (rotations never updated) stays far from it at this rotation.
    const Drag d;
    FemSettings s;
    s.refactorMode = RefactorMode::Synchronous;
    s.refactorDisplacement = 1e-9; // every solve
    auto fem = CorotationalFem::create(*d.bar.mesh, d.bar.fixed, s, d.bar.gravity);
    auto lin = CorotationalFem::create(*d.bar.mesh, d.bar.fixed, linearSettings(), d.bar.gravity);
    const int id = d.constrain(*fem), il = d.constrain(*lin);
    for (int k = 0; k <= 20; ++k) { // drag the end 24 mm down (the bar is 60 mm long)
        d.target(*fem, id, k, 1.2e-3);
        d.target(*lin, il, k, 1.2e-3);
        ASSERT_TRUE(fem->solve().finite);
        ASSERT_TRUE(lin->solve().finite);
    }
    const StaticReference early = fem->convergedStatic();
    ASSERT_TRUE(early.converged) << early.message << " residual " << early.residual << " after " << early.iterations;
    EXPECT_LE(early.energy, fem->corotationalEnergy(fem->positions()) + 1e-15);
    for (int k = 0; k < 40; ++k)
        ASSERT_TRUE(fem->solve().finite); // same target: the fixed-point iteration
    const StaticReference ref = fem->convergedStatic();
    ASSERT_TRUE(ref.converged) << ref.message;
    const double span = maxDistance(ref.x, fem->restPositions());
    EXPECT_GT(span, 0.02);
    EXPECT_LT(maxDistance(fem->positions(), ref.x), 1e-7 * span);
    EXPECT_LT(maxDistance(early.x, ref.x), 1e-7 * span); // the same x* from an earlier state
    // The linear FEM's answer, measured against its own reference, is far off.
    const StaticReference linRef = lin->convergedStatic();
    ASSERT_TRUE(linRef.converged) << linRef.message << " residual " << linRef.residual << " after "
                                  << linRef.iterations;
    EXPECT_GT(maxDistance(lin->positions(), linRef.x), 1e-3 * span);
    EXPECT_GT(lin->corotationalEnergy(lin->positions()), linRef.energy);
}

TEST(CorotationalFem, RefactorAtRejectsPositionsOfTheWrongSize) {
    Bar bar = makeBar();
    auto fem = CorotationalFem::create(*bar.mesh, bar.fixed, FemSettings{}, bar.gravity);
    std::string error;
    EXPECT_FALSE(fem->refactorAt({Vec3::Zero()}, &error));
    EXPECT_NE(error.find("refactorAt(): positions have the wrong size"), std::string::npos) << error;
}

namespace {

/// Floors under the bottom nodes of a sagging bar, one unilateral group each, started active: the
/// ones far below pull and are released, in cascades over several active-set iterations. Two groups
/// share the tip's row: the later one is rejected while the earlier (a pulling floor) holds it, and
/// enforced once that one is released.
struct Floors {
    Bar bar = makeBar({10, 2, 3});
    std::vector<int> ids;
    void addTo(CorotationalFem& fem, const std::vector<Vec3>& sagged) {
        const auto& p = bar.mesh->positions();
        int tip = -1, k = 0;
        for (int v = 0; v < static_cast<int>(p.size()); ++v)
            if (!fem.isFixed(v) && p[v].z() < 1e-9 && (tip < 0 || p[v].x() > p[tip].x())) tip = v;
        for (int v = 0; v < static_cast<int>(p.size()); ++v) {
            if (fem.isFixed(v) || p[v].z() > 1e-9 || v == tip) continue;
            const double sag = p[v].z() - sagged[v].z();
            ConstraintDesc d;
            d.kind = ConstraintKind::Unilateral;
            d.priority = 3;
            // alternately held half-way up and far below (pulling, released)
            d.rows.push_back({{{v, Vec3(0, 0, 1)}}, p[v].z() - (k++ % 3 == 0 ? 0.5 : 4.0) * sag});
            ids.push_back(fem.addConstraint(d));
        }
        const double sag = p[tip].z() - sagged[tip].z();
        for (double depth : {4.0, 0.5}) {
            ConstraintDesc d;
            d.kind = ConstraintKind::Unilateral;
            d.priority = 3;
            d.rows.push_back({{{tip, Vec3(0, 0, 1)}}, p[tip].z() - depth * sag});
            ids.push_back(fem.addConstraint(d));
        }
    }
};

} // namespace

TEST(CorotationalFem, ReleasedGroupsLeaveTheSchurFactorAsAFactorizationWouldDo) {
    Floors floors;
    FemSettings s = linearSettings();
    FemSettings ref = s;
    ref.incrementalSchur = false;
    auto fem = CorotationalFem::create(*floors.bar.mesh, floors.bar.fixed, s, floors.bar.gravity);
    auto plain = CorotationalFem::create(*floors.bar.mesh, floors.bar.fixed, ref, floors.bar.gravity);
    const std::vector<Vec3> sagged = fem->positions();
    floors.addTo(*fem, sagged);
    floors.addTo(*plain, sagged);
    ASSERT_GT(floors.ids.size(), 20u);
    const FemSolveStats a = fem->solve(), b = plain->solve();
    ASSERT_TRUE(a.finite && b.finite) << a.error << b.error;
    EXPECT_GE(a.activeSetIterations, 2) << "a release, then the factor without the released rows";
    EXPECT_EQ(a.activeSetIterations, b.activeSetIterations);
    EXPECT_EQ(a.rows, b.rows);
    EXPECT_EQ(a.redundant + a.incompatible, b.redundant + b.incompatible);
    int held = 0, released = 0;
    const size_t half = floors.ids.size() / 2;
    for (size_t i = 0; i < half; ++i) {
        const int id = floors.ids[i];
        ASSERT_EQ(fem->state(id).active, plain->state(id).active) << "group " << id;
        held += fem->state(id).active;
        released += !fem->state(id).active;
        EXPECT_NEAR(fem->state(id).lambda[0], plain->state(id).lambda[0],
                    1e-10 * (1 + std::abs(plain->state(id).lambda[0])));
    }
    EXPECT_GT(held, 0);
    EXPECT_GT(released, 0);
    // The tip's second floor (half-way up) is enforced once the first (far below, pulling) is released.
    const int first = floors.ids[floors.ids.size() - 2], second = floors.ids.back();
    EXPECT_FALSE(fem->state(first).active);
    EXPECT_TRUE(fem->state(second).active);
    EXPECT_EQ(fem->state(second).status[0], RowStatus::Enforced);
    EXPECT_EQ(plain->state(second).status[0], RowStatus::Enforced);
    const double scale = maxDistance(sagged, fem->restPositions());
    EXPECT_LT(maxDistance(fem->positions(), plain->positions()), 1e-10 * scale);
}

TEST(CorotationalFem, AStepDoesItsAmortizedWorkAtItsEndInWhatItsSolvesLeft) {
    // Prefetch with steps of three solves: the solves cache nothing ahead; endStep() caches
    // prefetchNodesPerSolve nodes when the step's budget allows, fewer when it allows less, none
    // when the step's own solves took it all (a burst of new constraints).
    const Drag d;
    FemSettings s;
    s.refactorMode = RefactorMode::Synchronous;
    s.refactorDisplacement = 1e9;
    s.prefetchNodesPerSolve = 2;
    s.stepSubstitutions = 18;
    auto stepped = CorotationalFem::create(*d.bar.mesh, d.bar.fixed, s, d.bar.gravity);
    auto plain = CorotationalFem::create(*d.bar.mesh, d.bar.fixed, s, d.bar.gravity);
    std::vector<int32_t> ahead;
    for (int32_t v = static_cast<int32_t>(plain->nodeCount()) - 1; ahead.size() < 8; --v)
        if (!plain->isFixed(v)) ahead.push_back(v);
    stepped->prefetchNodes(ahead);
    plain->prefetchNodes(ahead);
    for (int step = 0; step < 2; ++step) {
        stepped->beginStep();
        for (int solve = 0; solve < 3; ++solve) {
            const FemSolveStats a = stepped->solve(), b = plain->solve();
            ASSERT_TRUE(a.finite && b.finite);
            EXPECT_EQ(a.newCachedNodes, 0) << "step " << step << ", solve " << solve;
            EXPECT_EQ(a.substitutions, 0);
            EXPECT_EQ(b.newCachedNodes, std::max(0, std::min(2, 8 - 2 * (3 * step + solve))))
                << "no steps: every solve";
        }
        const FemSolveStats end = stepped->endStep();
        EXPECT_EQ(end.newCachedNodes, 2) << "step " << step;
        EXPECT_EQ(end.substitutions, 6);
    }
    EXPECT_EQ(stepped->cachedNodes(), 4);
    EXPECT_EQ(plain->cachedNodes(), 8);
    EXPECT_LT(maxDistance(stepped->positions(), plain->positions()), 1e-15) << "work moved, results unchanged";

    // A budget of 3 substitutions: one node.
    s.stepSubstitutions = 3;
    auto small = CorotationalFem::create(*d.bar.mesh, d.bar.fixed, s, d.bar.gravity);
    small->prefetchNodes(ahead);
    small->beginStep();
    ASSERT_TRUE(small->solve().finite);
    EXPECT_EQ(small->endStep().newCachedNodes, 1);
    // A step whose solve cached the four nodes of a new constraint (12 substitutions) leaves 6: two
    // nodes; one that took 12 of a budget of 12 leaves none.
    for (const int budget : {18, 12}) {
        s.stepSubstitutions = budget;
        auto burst = CorotationalFem::create(*d.bar.mesh, d.bar.fixed, s, d.bar.gravity);
        burst->prefetchNodes(ahead);
        burst->beginStep();
        d.constrain(*burst);
        const FemSolveStats a = burst->solve();
        ASSERT_TRUE(a.finite);
        ASSERT_EQ(a.newCachedNodes, 4);
        EXPECT_EQ(burst->endStep().newCachedNodes, budget == 18 ? 2 : 0) << "budget " << budget;
    }
    EXPECT_EQ(plain->endStep().substitutions, 0) << "without beginStep() endStep() does nothing";
}

TEST(CorotationalFem, AStepCarriesBetweenOneNodeAndItsShareAndTheSwapStillComes) {
    // Background refactorization with 4 carried nodes per solve (28 carried: 24 pinned, 4 constrained)
    // and steps of three solves: the solves carry nothing; endStep() carries 4 nodes (12 substitutions)
    // when the step left room, one when it left none; the swap still comes.
    const Drag d;
    FemSettings s;
    s.refactorMode = RefactorMode::Background;
    s.refactorDisplacement = 0.05;
    s.refactorLatencySteps = 1;
    s.refactorNodesPerSolve = 4;
    auto plain = CorotationalFem::create(*d.bar.mesh, d.bar.fixed, s, d.bar.gravity);
    s.stepSubstitutions = 12;
    auto stepped = CorotationalFem::create(*d.bar.mesh, d.bar.fixed, s, d.bar.gravity);
    s.stepSubstitutions = 0; // every step's budget taken: one node a step
    auto starved = CorotationalFem::create(*d.bar.mesh, d.bar.fixed, s, d.bar.gravity);
    std::vector<int32_t> pins;
    for (int32_t v = 0; pins.size() < 24; ++v)
        if (!plain->isFixed(v)) pins.push_back(v);
    std::vector<CorotationalFem*> all{plain.get(), stepped.get(), starved.get()};
    std::vector<int> ids;
    for (auto* fem : all) { // pinned and cached: carried by every refactorization
        fem->pinNodes(pins);
        fem->prefetchNodes(pins);
        for (int k = 0; k < 7; ++k) // cache the pins (prefetch, 4 a solve, no steps yet) before any refactorization
            ASSERT_TRUE(fem->solve().finite);
        ASSERT_EQ(fem->cachedNodes(), 24);
        ids.push_back(d.constrain(*fem));
    }
    std::vector<std::vector<int>> started(3), swapped(3);
    std::vector<int> carried(3, 0);
    for (int k = 0; k < 300; ++k) {
        for (size_t f = 0; f < all.size(); ++f) {
            CorotationalFem& fem = *all[f];
            const bool stepStart = f == 0 || k % 3 == 0;
            if (f > 0 && stepStart) fem.beginStep();
            d.target(fem, ids[f], k / 3);
            const bool pending = fem.refactorPending();
            const FemSolveStats a = fem.solve();
            ASSERT_TRUE(a.finite) << a.error;
            if (a.refactorStarted) started[f].push_back(k);
            if (a.refactored) swapped[f].push_back(k);
            if (f > 0 && pending && !a.refactored)
                EXPECT_EQ(a.substitutions % 3, a.substitutions > 0 ? 1 : 0)
                    << "stepped solves carry nothing (at most u's substitution), solve " << k;
            if (f > 0 && k % 3 == 2) {
                const FemSolveStats e = fem.endStep();
                if (e.substitutions > 0) {
                    EXPECT_EQ(e.substitutions, f == 1 ? 12 : 3) << "solve " << k; // less when the last nodes are done
                    carried[f] += e.substitutions == (f == 1 ? 12 : 3);
                }
            }
        }
    }
    EXPECT_GT(carried[1], 0);
    EXPECT_GT(carried[2], 0);
    for (size_t f = 0; f < all.size(); ++f)
        ASSERT_GE(swapped[f].size(), 1u) << "the new factor still takes effect, fem " << f;
    auto firstSwap = [&](size_t f) { return swapped[f][0] - started[f][0]; };
    EXPECT_LT(firstSwap(0), firstSwap(1)) << "carried once a step, not every solve";
    EXPECT_LT(firstSwap(1), firstSwap(2)) << "a node a step when the steps leave no room";
    EXPECT_LE(firstSwap(2), 3 * (1 + 28 + 2)) << "at least one node a step";
    EXPECT_GE(firstSwap(2), 3 * 28) << "28 nodes carried, one a step";
}
