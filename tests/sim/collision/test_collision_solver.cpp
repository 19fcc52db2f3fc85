#include "sim/collision/collision_solver.hpp"
#include "sim/collision/distance.hpp"
#include "sim/mesh/generators.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <random>

using namespace viscera::sim;
using ::testing::HasSubstr;

namespace {

/// A flat square of two triangles in z = 0 (normal +z), side L.
CollisionSurfaceDesc square(double L = 0.01, std::vector<double> w = {1, 1, 1, 1}) {
    CollisionSurfaceDesc d;
    d.restPositions = {Vec3(0, 0, 0), Vec3(L, 0, 0), Vec3(L, L, 0), Vec3(0, L, 0)};
    d.triangles = {{0, 1, 2}, {0, 2, 3}};
    d.inverseMass = std::move(w);
    return d;
}

/// One right triangle in z = 0 (normal +z), legs 1 cm, inverse mass 2 per vertex.
CollisionSurfaceDesc oneTriangle() {
    CollisionSurfaceDesc d;
    d.restPositions = {Vec3(0, 0, 0), Vec3(0.01, 0, 0), Vec3(0, 0.01, 0)};
    d.triangles = {{0, 1, 2}};
    d.inverseMass = {2, 2, 2};
    return d;
}

ToolShape sphereAt(double r, const Vec3& c) {
    ToolShape t = ToolShape::sphere(r);
    ToolShape::Pose p = ToolShape::Pose::Identity();
    p.translation() = c;
    t.setPose(p);
    return t;
}

} // namespace

// Finite-difference check of the unified triangle constraint [A eq. 5.8] (both forms) and of the
// polygon point–triangle constraint, over random configurations.
TEST(CollisionConstraint, GradientsMatchFiniteDifferences) {
    std::mt19937 rng(2);
    std::uniform_real_distribution<double> u(-0.01, 0.01);
    for (int trial = 0; trial < 50; ++trial) {
        std::array<Vec3, 3> x, target;
        for (int k = 0; k < 3; ++k) {
            x[k] = Vec3(u(rng), u(rng), u(rng));
            target[k] = x[k] + Vec3(u(rng), u(rng), u(rng));
        }
        const Vec3 bary = Vec3(std::abs(u(rng)), std::abs(u(rng)), std::abs(u(rng))).normalized();
        const Vec3 b = bary / bary.sum(), q(u(rng), u(rng), 0.02 + u(rng));
        for (int form = 0; form < 3; ++form) {
            auto eval = [&](const std::array<Vec3, 3>& y, std::array<Vec3, 3>* g) {
                if (form == 2) return pointTriangleConstraint(y, b, q, 0.005, g);
                return unifiedTriangleConstraint(y, target, form == 1, g);
            };
            std::array<Vec3, 3> grad;
            eval(x, &grad);
            const double h = 1e-7;
            for (int k = 0; k < 3; ++k)
                for (int a = 0; a < 3; ++a) {
                    auto xp = x, xm = x;
                    xp[k][a] += h;
                    xm[k][a] -= h;
                    const double fd = (eval(xp, nullptr) - eval(xm, nullptr)) / (2 * h);
                    EXPECT_NEAR(grad[k][a], fd, 1e-6 * std::max(1.0, std::abs(fd)))
                        << "form " << form << " vertex " << k << " axis " << a;
                }
        }
    }
    // Zero at the targets.
    std::array<Vec3, 3> x = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
    EXPECT_EQ(unifiedTriangleConstraint(x, x, false, nullptr), 0.0);
    EXPECT_EQ(unifiedTriangleConstraint(x, x, true, nullptr), 0.0);
}

TEST(CollisionSolver, CircumsphereContactTranslatesTheTriangleAsOne) {
    CollisionSettings s;
    s.circumsphere.energyScale = 0;
    s.maxCorrectionPerStep = 1.0; // geometry only: no per-step cap
    auto col = CollisionSolver::create(square(), s);
    // Sphere tool of radius 5 mm just above the first triangle, overlapping its circumsphere.
    const Vec3 c0 = circumcircle(Vec3(0, 0, 0), Vec3(0.01, 0, 0), Vec3(0.01, 0.01, 0)).centre;
    ToolShape tool = sphereAt(0.005, c0 + Vec3(0, 0, 0.005));
    std::vector<Vec3> x = square().restPositions;
    const std::vector<Vec3> x0 = x;
    col->beginStep(x, tool, 1e-3);
    EXPECT_EQ(col->stats().candidates, 2);
    EXPECT_GT(col->iterate(x, tool), 0);
    // Triangle 0 moved rigidly by one vector (its vertex 0 and 2 are shared with triangle 1,
    // which also collides; check the sphere of each no longer overlaps after a few sweeps).
    for (int k = 0; k < 10; ++k)
        col->iterate(x, tool);
    for (int32_t t = 0; t < 2; ++t) {
        const Sphere sp = col->triangleSphere(t, x);
        EXPECT_GE((sp.centre - tool.parts()[0].a).norm(), sp.radius + 0.005 - 1e-9);
    }
    // Pushed down (into the tissue), not sideways much.
    for (int v = 0; v < 4; ++v)
        EXPECT_LT(x[v].z(), x0[v].z());
    EXPECT_EQ(col->contactVertices(), (std::vector<int32_t>{0, 1, 2, 3}));
}

TEST(CollisionSolver, UnifiedResponseMovesAllThreeVerticesEqually) {
    const CollisionSurfaceDesc d = oneTriangle();
    for (bool squared : {false, true}) {
        CollisionSettings s;
        s.squaredForm = squared;
        auto col = CollisionSolver::create(d, s);
        const Sphere sp = col->triangleSphere(0, d.restPositions);
        ToolShape tool = sphereAt(0.003, sp.centre + Vec3(0, 0, sp.radius + 0.002));
        std::vector<Vec3> x = d.restPositions;
        col->beginStep(x, tool, 1e-3);
        ASSERT_EQ(col->iterate(x, tool), 1);
        const Vec3 m0 = x[0] - d.restPositions[0];
        for (int v = 1; v < 3; ++v)
            EXPECT_LT((x[v] - d.restPositions[v] - m0).norm(), 1e-15);
        // Root form resolves the 1 mm overlap in one projection; the squared form halves it.
        EXPECT_NEAR(m0.z(), squared ? -0.0005 : -0.001, 1e-12);
    }
}

// The safe cone [A §5.2.1]: a tool meeting the circumsphere through the cap over the triangle
// is a contact; one meeting its side (the part of the sphere inside the tissue) is not, unless
// safeConeOnly is off.
TEST(CollisionSolver, CircumsphereContactsOnlyThroughTheSafeCone) {
    const CollisionSurfaceDesc d = oneTriangle();
    for (bool coneOnly : {true, false}) {
        CollisionSettings s;
        s.circumsphere.energyScale = 0;
        s.safeConeOnly = coneOnly;
        auto col = CollisionSolver::create(d, s);
        const Sphere sp = col->triangleSphere(0, d.restPositions);
        // Flat, unstrained: H3 = 1, ε = 0, so the cone's half-angle is the safe angle θ.
        EXPECT_NEAR(sp.coneCos, std::cos(s.circumsphere.safeAngle), 1e-12);
        EXPECT_NEAR(sp.coneAxis.z(), 1.0, 1e-12);
        const double toolR = 0.003;
        for (double angleDeg : {0.0, 20.0, 45.0, 80.0}) {
            SCOPED_TRACE("cone only " + std::to_string(coneOnly) + ", tool at " + std::to_string(angleDeg) +
                         " deg from the normal");
            const double a = angleDeg * M_PI / 180;
            // 1 mm overlap with the sphere, in direction a from the normal.
            const Vec3 dir(std::sin(a), 0, std::cos(a));
            ToolShape tool = sphereAt(toolR, sp.centre + (sp.radius + toolR - 0.001) * dir);
            EXPECT_EQ(sp.inSafeCone(tool.parts()[0].a), angleDeg < 30);
            std::vector<Vec3> x = d.restPositions;
            col->beginStep(x, tool, 1e-3);
            const int contacts = col->iterate(x, tool);
            const bool expected = !coneOnly || angleDeg < 30;
            EXPECT_EQ(contacts, expected ? 1 : 0);
            EXPECT_EQ(x == d.restPositions, !expected);
        }
    }
    // The bounding sphere has no safe cone: every overlap is a contact.
    EXPECT_TRUE(boundingSphere(d.restPositions[0], d.restPositions[1], d.restPositions[2])
                    .inSafeCone(Vec3(0.003, 0.003, -0.1)));
}

TEST(CollisionSolver, PolygonContactKeepsTheMargin) {
    CollisionSettings s;
    s.method = CollisionMethod::Polygon;
    s.polygonMargin = 0.001;
    s.maxCorrectionPerStep = 1.0;
    auto col = CollisionSolver::create(square(0.02), s);
    ToolShape tool = sphereAt(0.004, Vec3(0.012, 0.006, 0.003)); // 1 mm into the face
    std::vector<Vec3> x = square(0.02).restPositions;
    col->beginStep(x, tool, 1e-3);
    for (int k = 0; k < 20; ++k)
        col->iterate(x, tool);
    const TrianglePoint tp = closestPointOnTriangle(tool.parts()[0].a, x[0], x[1], x[2]);
    EXPECT_NEAR((tp.point - tool.parts()[0].a).norm(), 0.005, 1e-9);
}

// The [Eri04] per-feature polygon method: a face, an edge and a vertex contact each end at the
// margin, by the constraint of their own feature.
TEST(CollisionSolver, PolygonFeaturesResolveFaceEdgeAndVertexContacts) {
    CollisionSettings s;
    s.method = CollisionMethod::PolygonFeatures;
    s.polygonMargin = 0.001;
    s.maxCorrectionPerStep = 1.0;
    const double L = 0.02, reach = 0.005;
    struct Case {
        const char* feature;
        Vec3 centre;
    };
    const Case cases[] = {{"face", Vec3(0.012, 0.006, 0.003)},          // 1 mm into the face
                          {"edge", Vec3(0.010, -0.003, 0.0025)},        // beyond edge (0, 1)
                          {"vertex", Vec3(L + 0.003, -0.003, 0.0015)}}; // beyond corner 1
    for (const Case& c : cases) {
        auto col = CollisionSolver::create(square(L), s);
        ToolShape tool = sphereAt(0.004, c.centre);
        std::vector<Vec3> x = square(L).restPositions;
        const double before = std::min(closestPointsSegmentTriangle(c.centre, c.centre, x[0], x[1], x[2]).distance,
                                       closestPointsSegmentTriangle(c.centre, c.centre, x[0], x[2], x[3]).distance);
        ASSERT_LT(before, reach - 2e-4) << c.feature << ": the case starts in contact";
        col->beginStep(x, tool, 1e-3);
        int contacts = 0;
        for (int k = 0; k < 40; ++k)
            contacts += col->iterate(x, tool);
        EXPECT_GT(contacts, 0) << c.feature;
        const double after = std::min(closestPointsSegmentTriangle(c.centre, c.centre, x[0], x[1], x[2]).distance,
                                      closestPointsSegmentTriangle(c.centre, c.centre, x[0], x[2], x[3]).distance);
        EXPECT_NEAR(after, reach, 1e-6) << c.feature;
        for (const Vec3& p : x)
            EXPECT_TRUE(p.allFinite()) << c.feature;
    }
    // The vertex case moves vertex 1 to the reach along the line from the centre.
    auto col = CollisionSolver::create(square(L), s);
    ToolShape tool = sphereAt(0.004, cases[2].centre);
    std::vector<Vec3> x = square(L).restPositions;
    col->beginStep(x, tool, 1e-3);
    for (int k = 0; k < 40; ++k)
        col->iterate(x, tool);
    EXPECT_NEAR((x[1] - cases[2].centre).norm(), reach, 1e-6);
    EXPECT_EQ(x[3], square(L).restPositions[3]) << "the far corner is not a candidate contact";
}

TEST(CollisionSolver, MethodNamesRoundTrip) {
    for (CollisionMethod m : {CollisionMethod::Circumsphere, CollisionMethod::BoundingSphere, CollisionMethod::Polygon,
                              CollisionMethod::PolygonFeatures}) {
        CollisionMethod back = CollisionMethod::Circumsphere;
        EXPECT_TRUE(parseCollisionMethod(toString(m), back)) << toString(m);
        EXPECT_EQ(back, m);
        EXPECT_THAT(kCollisionMethodNames, HasSubstr(toString(m)));
    }
    CollisionMethod m = CollisionMethod::Polygon;
    EXPECT_FALSE(parseCollisionMethod("sdf", m));
    EXPECT_EQ(m, CollisionMethod::Polygon) << "unchanged on an unknown name";
}

TEST(CollisionSolver, CorrectionPerStepIsCapped) {
    CollisionSettings s;
    s.maxCorrectionPerStep = 0.001;
    auto col = CollisionSolver::create(square(), s);
    ToolShape tool = sphereAt(0.006, Vec3(0.005, 0.005, 0.0)); // deep inside
    std::vector<Vec3> x = square().restPositions;
    col->beginStep(x, tool, 1e-3);
    for (int k = 0; k < 10; ++k)
        col->iterate(x, tool);
    for (int v = 0; v < 4; ++v)
        EXPECT_LE((x[v] - square().restPositions[v]).norm(), 0.001 + 1e-15);
}

TEST(CollisionSolver, FixedVerticesNeverMove) {
    for (CollisionMethod m : {CollisionMethod::Circumsphere, CollisionMethod::BoundingSphere, CollisionMethod::Polygon,
                              CollisionMethod::PolygonFeatures}) {
        CollisionSettings s;
        s.method = m;
        auto col = CollisionSolver::create(square(0.01, {0, 1, 1, 0}), s);
        ToolShape tool = sphereAt(0.004, Vec3(0.005, 0.005, 0.001));
        std::vector<Vec3> x = square().restPositions;
        col->beginStep(x, tool, 1e-3);
        for (int k = 0; k < 5; ++k)
            col->iterate(x, tool);
        EXPECT_EQ(x[0], Vec3(0, 0, 0)) << toString(m);
        EXPECT_EQ(x[3], Vec3(0, 0.01, 0)) << toString(m);
        EXPECT_LT(x[1].z(), 0) << toString(m);
    }
}

// [A §5.2.4]: factors are refreshed only when |S/S_ref − 1| >= δ.
TEST(CollisionSolver, UpdateThresholdTriggers) {
    CollisionSettings s;
    s.circumsphere.updateThreshold = 0.2;
    s.circumsphere.energyScale = 0.01;
    auto col = CollisionSolver::create(square(), s);
    ToolShape tool = sphereAt(0.001, Vec3(0.005, 0.005, 0.05)); // far above
    ToolShape big = sphereAt(0.05, Vec3(0.005, 0.005, 0.04));   // its box covers the square
    std::vector<Vec3> x = square().restPositions;
    col->beginStep(x, big, 1e-3);
    EXPECT_EQ(col->stats().candidates, 2);
    EXPECT_EQ(col->stats().factorUpdates, 0);
    // Stretch vertex 2 so that triangle areas grow by 10 %: below δ, factors kept.
    std::vector<Vec3> y = x;
    y[2] = Vec3(0.011, 0.011, 0);
    col->beginStep(y, big, 1e-3);
    EXPECT_EQ(col->stats().factorUpdates, 0);
    EXPECT_EQ(col->energyFactor(0), 0.0);
    // 30 %: refreshed; the energy factor now reflects the stretch.
    y[2] = Vec3(0.013, 0.013, 0);
    col->beginStep(y, big, 1e-3);
    EXPECT_EQ(col->stats().factorUpdates, 2);
    EXPECT_GT(col->energyFactor(0), 0.0);
    // Same shape again: relative to the refreshed reference, no change.
    col->beginStep(y, big, 1e-3);
    EXPECT_EQ(col->stats().factorUpdates, 0);
    // Outside the tool's box nothing is tested.
    col->beginStep(x, tool, 1e-3);
    EXPECT_EQ(col->stats().candidates, 0);
    // δ = 0: every candidate refreshed every step.
    s.circumsphere.updateThreshold = 0;
    auto always = CollisionSolver::create(square(), s);
    always->beginStep(x, big, 1e-3);
    EXPECT_EQ(always->stats().factorUpdates, 2);
    always->beginStep(x, big, 1e-3);
    EXPECT_EQ(always->stats().factorUpdates, 2);
}

TEST(CollisionSolver, CurvatureFactorShrinksSpheresOnEdgesOfABox) {
    auto mesh = makeBoxTetMesh({Vec3::Zero(), Vec3(0.04, 0.04, 0.02), {4, 4, 2}});
    mesh->requireLevel(3);
    auto col = CollisionSolver::create(
        CollisionSurfaceDesc::fromTetMesh(*mesh, std::vector<double>(mesh->vertexCount(), 1.0)), {});
    double flatMin = 1, edgeMax = 0;
    const auto& x = mesh->positions();
    for (int32_t t = 0; t < static_cast<int32_t>(col->triangleCount()); ++t) {
        const Tri& f = col->triangles()[t];
        bool onTopInterior = true;
        for (int32_t v : f)
            onTopInterior &= x[v].z() > 0.02 - 1e-9 && x[v].x() > 1e-9 && x[v].x() < 0.04 - 1e-9 && x[v].y() > 1e-9 &&
                             x[v].y() < 0.04 - 1e-9;
        bool touchesCorner = false;
        for (int32_t v : f)
            touchesCorner |= (x[v].x() < 1e-9 || x[v].x() > 0.04 - 1e-9) &&
                             (x[v].y() < 1e-9 || x[v].y() > 0.04 - 1e-9) && x[v].z() > 0.02 - 1e-9;
        if (onTopInterior) flatMin = std::min(flatMin, col->curvatureFactor(t));
        if (touchesCorner) edgeMax = std::max(edgeMax, col->curvatureFactor(t));
    }
    EXPECT_EQ(flatMin, 1.0);
    EXPECT_LT(edgeMax, 1.0);
}

TEST(CollisionSolver, CreateRejectsBadInputWithMessages) {
    auto d = square();
    d.triangles.push_back({0, 1, 9});
    EXPECT_THAT([&] { CollisionSolver::create(d, {}); },
                ::testing::ThrowsMessage<std::invalid_argument>(
                    HasSubstr("triangle 2 references vertex 9 (surface has 4 vertices)")));
    d = square();
    d.inverseMass = {1, 1, -1, 1};
    EXPECT_THAT([&] { CollisionSolver::create(d, {}); },
                ::testing::ThrowsMessage<std::invalid_argument>(HasSubstr("vertex 2")));
    d = square();
    d.inverseMass = {1, 1};
    EXPECT_THROW(CollisionSolver::create(d, {}), std::invalid_argument);
    CollisionSettings s;
    s.circumsphere.safeAngle = 2.0;
    EXPECT_THAT([&] { CollisionSolver::create(square(), s); },
                ::testing::ThrowsMessage<std::invalid_argument>(HasSubstr("safe angle")));
}

TEST(CollisionSolver, BroadPhaseFindsEveryTriangleWhoseSphereBoxMeetsTheTool) {
    // The broad phase skips the sphere of a triangle whose vertex box, grown by a bound on the
    // sphere's reach, misses the tool: it must still find exactly the triangles whose sphere box
    // (safe-cone part or whole sphere) meets the tool's box. Checked by brute force on a box
    // surface with random dents, some triangles squashed to slivers, stale factors and tools all
    // over it.
    auto mesh = makeBoxTetMesh({Vec3::Zero(), Vec3(0.04, 0.03, 0.01), {8, 6, 2}});
    mesh->requireLevel(3);
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    int found = 0, missed = 0; // the trials must both find and leave out triangles
    for (bool safeCone : {true, false}) {
        CollisionSettings s;
        s.safeConeOnly = safeCone;
        s.circumsphere.energyScale = 0.002;
        auto col = CollisionSolver::create(
            CollisionSurfaceDesc::fromTetMesh(*mesh, std::vector<double>(mesh->vertexCount(), 1.0)), s);
        for (int trial = 0; trial < 30; ++trial) {
            std::vector<Vec3> x = mesh->positions();
            for (Vec3& p : x)
                p += 0.0015 * Vec3(u(rng), u(rng), u(rng));
            for (size_t t = 0; t < col->triangleCount(); t += 7) { // slivers: a vertex onto an edge midpoint
                const Tri& f = col->triangles()[t];
                x[f[2]] = 0.5 * (x[f[0]] + x[f[1]]) + 1e-5 * Vec3(u(rng), u(rng), u(rng));
            }
            if (trial % 3 == 0) col->refreshAllFactors(x); // else factors from an earlier shape
            const ToolShape tool = sphereAt(0.001 + 0.004 * (u(rng) + 1),
                                            Vec3(0.02 + 0.03 * u(rng), 0.015 + 0.025 * u(rng), 0.005 + 0.015 * u(rng)));
            const auto tb = tool.bounds();
            int expected = 0;
            for (int32_t t = 0; t < static_cast<int32_t>(col->triangleCount()); ++t) {
                const Sphere sp = col->triangleSphere(t, x);
                Vec3 lo = sp.centre - Vec3::Constant(sp.radius), hi = sp.centre + Vec3::Constant(sp.radius);
                if (safeCone && sp.coneCos > -1) {
                    const double c = std::clamp(sp.coneCos, 0.0, 1.0);
                    const Vec3 rim = sp.centre + sp.radius * c * sp.coneAxis;
                    const Vec3 R = Vec3::Constant(sp.radius * std::sqrt(1 - c * c));
                    lo = (rim - R).cwiseMin(sp.centre);
                    hi = (rim + R).cwiseMax(sp.centre);
                }
                expected += (lo.array() <= tb[1].array()).all() && (tb[0].array() <= hi.array()).all();
            }
            col->beginStep(x, tool, 1e-3);
            EXPECT_EQ(col->stats().candidates, expected) << "trial " << trial << (safeCone ? " safe cone" : "");
            found += expected;
            missed += static_cast<int>(col->triangleCount()) - expected;
        }
    }
    EXPECT_GT(found, 0);
    EXPECT_GT(missed, 0);
}

// The contact force of a step is Σ m Δx / h² over the vertices the contacts moved: a sphere
// pressed into a fixed-mass patch gives the momentum its pushes put in, along the push, and no
// force from a fixed vertex or from a step without contact.
TEST(CollisionSolver, ContactForceIsTheMassWeightedPushOverHSquared) {
    const double h = 1e-3;
    for (const double w3 : {1.0, 0.0}) { // vertex 3 free, then fixed
        CollisionSettings s;
        s.method = CollisionMethod::Polygon;
        auto solver = CollisionSolver::create(square(0.01, {1, 1, 1, w3}), s);
        std::vector<Vec3> x = {Vec3(0, 0, 0), Vec3(0.01, 0, 0), Vec3(0.01, 0.01, 0), Vec3(0, 0.01, 0)};
        const std::vector<Vec3> start = x;
        const ToolShape tool = sphereAt(0.004, Vec3(0.004, 0.005, 0.003)); // reaches 1 mm (+ margin) below z = 0
        solver->beginStep(x, tool, h);
        EXPECT_EQ(solver->contactForce(), Vec3::Zero()) << "nothing pushed yet";
        for (int it = 0; it < 4; ++it)
            solver->iterate(x, tool);
        Vec3 expected = Vec3::Zero();
        const std::vector<double> w = {1, 1, 1, w3};
        for (size_t v = 0; v < x.size(); ++v)
            if (w[v] > 0) expected += (x[v] - start[v]) / w[v];
        expected /= h * h;
        const Vec3 f = solver->contactForce();
        ASSERT_GT(expected.norm(), 0) << "the sphere pushed the patch";
        EXPECT_LT((f - expected).norm(), 1e-9 * expected.norm()) << f.transpose() << " vs " << expected.transpose();
        EXPECT_LT(f.z(), 0) << "the tissue is pushed down, away from the tool above it";
        EXPECT_TRUE(f.allFinite());
    }
    CollisionSettings s;
    auto solver = CollisionSolver::create(square(), s);
    std::vector<Vec3> x = {Vec3(0, 0, 0), Vec3(0.01, 0, 0), Vec3(0.01, 0.01, 0), Vec3(0, 0.01, 0)};
    const ToolShape far = sphereAt(0.002, Vec3(0.005, 0.005, 0.05));
    solver->beginStep(x, far, h);
    solver->iterate(x, far);
    EXPECT_EQ(solver->contactForce(), Vec3::Zero()) << "no contact, no force";
}
