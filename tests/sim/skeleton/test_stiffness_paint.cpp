// Poly6 brush [A eq. 4.26–4.28]: the kernel against an independent evaluation to 1e-12, stroke
// selection through the skeleton, accumulation, clamping, validation and repeatability.
#include "sim/mesh/generators.hpp"
#include "sim/skeleton/stiffness_paint.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <set>

using namespace viscera::sim;
using ::testing::HasSubstr;

namespace {

/// Independent evaluation of the (sign-corrected) eq. 4.28 in long double. (h − v)(h + v) is
/// exact in long double for doubles h, v, so the reference stays accurate for v just below h.
long double referenceKernel(long double v, long double h) {
    if (v >= h) return 0.0L;
    const long double d = (h - v) * (h + v);
    return 315.0L / (64.0L * std::numbers::pi_v<long double> * std::pow(h, 9.0L)) * d * d * d;
}

void expectRel(double got, long double ref, double tol, const std::string& what) {
    if (ref == 0.0L) {
        EXPECT_EQ(got, 0.0) << what;
        return;
    }
    EXPECT_LE(std::abs(static_cast<long double>(got) - ref) / std::abs(ref), tol) << what << " got " << got;
}

/// A straight bar along x with a centre-line skeleton (as in test_skeleton_map.cpp).
struct Bar {
    std::unique_ptr<TetMesh> mesh;
    Skeleton skeleton;
};
Bar makeBar(int m) {
    Bar b;
    b.mesh = makeBoxTetMesh({Vec3(0, -0.01, -0.01), Vec3(0.1, 0.02, 0.02), {20, 4, 4}});
    b.mesh->requireLevel(2);
    for (int j = 0; j < m; ++j)
        b.skeleton.nodes.emplace_back(0.1 * (j + 0.5) / m, 0, 0);
    for (int j = 0; j + 1 < m; ++j)
        b.skeleton.edges.push_back({j, j + 1});
    b.skeleton.vertexNode.assign(b.mesh->vertexCount(), kNone);
    for (size_t i = 0; i < b.mesh->vertexCount(); ++i)
        if (b.mesh->isBoundaryVertex(static_cast<int32_t>(i)))
            b.skeleton.vertexNode[i] =
                std::clamp(static_cast<int32_t>(std::floor(b.mesh->positions()[i].x() / 0.1 * m)), 0, m - 1);
    return b;
}

std::string strokeError(const BrushStroke& s) {
    try {
        validateStroke(s, 4, "vessel");
    } catch (const std::invalid_argument& e) {
        return e.what();
    }
    return "no error";
}

} // namespace

TEST(Poly6Kernel, MatchesEq428To1e12) {
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (double h : {1e-3, 0.004, 0.01, 0.0371, 0.5, 1.0, 3.0}) {
        // Special points: centre, peak value 315/(64π h³), just below h, at h and beyond.
        expectRel(poly6Kernel(0.0, h), 315.0L / (64.0L * std::numbers::pi_v<long double> * h * h * h), 1e-12, "v=0");
        for (double f : {1e-12, 1e-6, 0.25, 0.5, 0.9, 1 - 1e-6, 1 - 1e-12})
            expectRel(poly6Kernel(f * h, h), referenceKernel(f * h, h), 1e-12, "v/h=" + std::to_string(f));
        const double below = std::nextafter(h, 0.0);
        expectRel(poly6Kernel(below, h), referenceKernel(below, h), 1e-12, "v=nextafter(h,0)");
        EXPECT_GT(poly6Kernel(below, h), 0.0);
        EXPECT_EQ(poly6Kernel(h, h), 0.0);
        EXPECT_EQ(poly6Kernel(std::nextafter(h, 10.0), h), 0.0);
        EXPECT_EQ(poly6Kernel(2 * h, h), 0.0);
        EXPECT_EQ(poly6Kernel(1e300, h), 0.0);
        for (int k = 0; k < 2000; ++k) {
            const double v = 1.2 * h * unit(rng);
            const double got = poly6Kernel(v, h);
            expectRel(got, referenceKernel(v, h), 1e-12, "random v");
            EXPECT_GE(got, 0.0); // the sign-corrected kernel is non-negative
            // The thesis' printed form (v² − h²)³ is the negative of ours inside the support.
            if (v < 0.99 * h) {
                const double printed = 315.0 / (64.0 * std::numbers::pi * std::pow(h, 9)) * std::pow(v * v - h * h, 3);
                EXPECT_NEAR(got, -printed, 1e-12 * std::abs(printed));
            }
        }
    }
    // Normalization: ∫_ball W dV = 1 (midpoint rule in r, 4π r² dr).
    const double h = 0.02;
    double integral = 0;
    const int steps = 200000;
    for (int k = 0; k < steps; ++k) {
        const double r = (k + 0.5) * h / steps;
        integral += poly6Kernel(r, h) * 4 * std::numbers::pi * r * r * h / steps;
    }
    EXPECT_NEAR(integral, 1.0, 1e-9);
    EXPECT_THROW(poly6Kernel(0.1, 0.0), std::invalid_argument);
    EXPECT_THROW(poly6Kernel(0.1, -1.0), std::invalid_argument);
    EXPECT_THROW(poly6Kernel(-0.1, 1.0), std::invalid_argument);
    EXPECT_THROW(poly6Kernel(std::nan(""), 1.0), std::invalid_argument);
    EXPECT_THROW(poly6Kernel(0.1, INFINITY), std::invalid_argument);
}

TEST(StiffnessPaint, StrokesAddTheKernelToNodesSelectedThroughTheSkeleton) {
    Bar b = makeBar(10);
    const auto& x = b.mesh->positions();
    std::vector<BrushStroke> strokes(3);
    strokes[0] = {Vec3(0.03, 0.004, 0.0), 0.018, 2.5, BrushScale::Peak};
    strokes[1] = {Vec3(0.07, -0.003, 0.002), 0.012, -0.4, BrushScale::Peak};
    strokes[2] = {Vec3(0.05, 0.0, 0.0), 0.015, 1e-6, BrushScale::Kernel}; // m³ × 1/m³
    PaintParams params;
    params.baseWeight = 1.0;
    const StiffnessPaintResult r = bakeStiffnessPaint(*b.mesh, b.skeleton, strokes, params);
    ASSERT_EQ(r.weights.size(), x.size());
    EXPECT_EQ(r.map.coveredCount(), x.size());

    // Independent evaluation: W_i = base + Σ_strokes [i selected] · a · kernel(|x_i − c|).
    std::vector<long double> expected(x.size(), 1.0L);
    for (size_t k = 0; k < strokes.size(); ++k) {
        const BrushStroke& s = strokes[k];
        std::set<int32_t> selected;
        for (size_t j = 0; j < b.skeleton.nodes.size(); ++j)
            if ((b.skeleton.nodes[j] - s.center).norm() < s.radius)
                for (int32_t q = r.map.start[j]; q < r.map.start[j + 1]; ++q)
                    selected.insert(r.map.members[q]);
        EXPECT_EQ(r.report.strokeSelected[k], selected.size());
        EXPECT_GT(selected.size(), 0u);
        for (int32_t i : selected) {
            const long double v = (x[i] - s.center).norm();
            const long double w = referenceKernel(v, s.radius);
            expected[i] +=
                s.scale == BrushScale::Peak ? s.amplitude * w / referenceKernel(0.0L, s.radius) : s.amplitude * w;
        }
    }
    size_t changed = 0;
    for (size_t i = 0; i < x.size(); ++i) {
        EXPECT_NEAR(r.weights[i], static_cast<double>(expected[i]), 1e-12 * static_cast<double>(expected[i]))
            << "node " << i;
        changed += r.weights[i] != 1.0;
    }
    EXPECT_GT(changed, 20u);
    EXPECT_EQ(r.report.clampedLow + r.report.clampedHigh, 0u);
    EXPECT_GT(r.report.maxWeight, 3.0); // stroke 0 adds up to 2.5 near its centre, stroke 2 ~0.05
    EXPECT_LT(r.report.minWeight, 1.0);

    // Repeat runs are bit-identical.
    EXPECT_EQ(bakeStiffnessPaint(*b.mesh, b.skeleton, strokes, params).weights, r.weights);
}

TEST(StiffnessPaint, KernelScaleWithUnitAmplitudeIsEq426AsPrinted) {
    Bar b = makeBar(8);
    BrushStroke s{Vec3(0.05, 0, 0), 0.03, 1.0, BrushScale::Kernel};
    PaintParams p;
    p.maxWeight = 1e12;
    const StiffnessPaintResult r = bakeStiffnessPaint(*b.mesh, b.skeleton, {s}, p);
    // h = 0.03 reaches all nodes of a centre slab; their skeleton nodes lie inside the brush.
    for (size_t i = 0; i < b.mesh->vertexCount(); ++i) {
        const double v = (b.mesh->positions()[i] - s.center).norm();
        if (std::abs(b.mesh->positions()[i].x() - 0.05) > 0.006) continue; // node 3, 4 Π_j only
        EXPECT_NEAR(r.weights[i], 1.0 + poly6Kernel(v, s.radius), 1e-12 * r.weights[i]);
    }
}

TEST(StiffnessPaint, SelectionGoesThroughTheSkeleton) {
    // A brush that covers mesh nodes but no skeleton node changes nothing: the skeleton selects.
    Bar b = makeBar(4); // nodes at x = 0.0125, 0.0375, 0.0625, 0.0875
    BrushStroke s{Vec3(0.025, 0.01, 0.01), 0.011, 5.0, BrushScale::Peak};
    for (const Vec3& p : b.skeleton.nodes)
        ASSERT_GE((p - s.center).norm(), s.radius);
    const StiffnessPaintResult r = bakeStiffnessPaint(*b.mesh, b.skeleton, {s});
    EXPECT_EQ(r.report.strokeSelected[0], 0u);
    for (double w : r.weights)
        EXPECT_EQ(w, 1.0);
}

TEST(StiffnessPaint, TheSphereReachAlsoChangesTheNodesTheBrushTouches) {
    // The brush of SelectionGoesThroughTheSkeleton, reaching by sphere: every node strictly inside
    // the brush changes by the kernel at its own distance, no other.
    Bar b = makeBar(4);
    BrushStroke s{Vec3(0.025, 0.01, 0.01), 0.011, 5.0, BrushScale::Peak};
    s.reach = BrushReach::Sphere;
    const StiffnessPaintResult r = bakeStiffnessPaint(*b.mesh, b.skeleton, {s});
    size_t inside = 0;
    for (size_t i = 0; i < b.mesh->vertexCount(); ++i) {
        const double v = (b.mesh->positions()[i] - s.center).norm();
        if (v < s.radius) {
            ++inside;
            const long double k = referenceKernel(v, s.radius) / referenceKernel(0.0L, s.radius);
            EXPECT_NEAR(r.weights[i], static_cast<double>(1.0L + 5.0L * k), 1e-12 * r.weights[i]) << "node " << i;
        } else {
            EXPECT_EQ(r.weights[i], 1.0) << "node " << i << " outside the brush";
        }
    }
    EXPECT_GT(inside, 0u);
    EXPECT_EQ(r.report.strokeSelected[0], inside);
    // reaching by skeleton as well: a brush over skeleton nodes selects their members and the
    // nodes inside it, the union
    BrushStroke t{Vec3(0.05, 0.0, 0.0), 0.02, 1.0, BrushScale::Peak};
    t.reach = BrushReach::Sphere;
    const StiffnessPaintResult both = bakeStiffnessPaint(*b.mesh, b.skeleton, {t});
    t.reach = BrushReach::Skeleton;
    const StiffnessPaintResult skel = bakeStiffnessPaint(*b.mesh, b.skeleton, {t});
    EXPECT_GE(both.report.strokeSelected[0], skel.report.strokeSelected[0]);
    for (size_t i = 0; i < b.mesh->vertexCount(); ++i)
        if (skel.weights[i] != 1.0) EXPECT_EQ(both.weights[i], skel.weights[i]) << "node " << i;
}

TEST(StiffnessPaint, WeightsAreClampedToThePositiveFloorAndCeiling) {
    Bar b = makeBar(10);
    PaintParams p;
    p.minWeight = 0.05;
    p.maxWeight = 3.0;
    // A huge softening stroke: every node with a non-zero kernel and a large enough increment
    // lands exactly on the floor, never at or below zero.
    std::vector<BrushStroke> strokes = {{Vec3(0.05, 0, 0), 0.02, -1e6, BrushScale::Peak}};
    StiffnessPaintResult r = bakeStiffnessPaint(*b.mesh, b.skeleton, strokes, p);
    EXPECT_GT(r.report.clampedLow, 0u);
    size_t atFloor = 0;
    for (double w : r.weights) {
        EXPECT_TRUE(std::isfinite(w));
        EXPECT_GE(w, p.minWeight);
        atFloor += w == p.minWeight;
    }
    EXPECT_EQ(atFloor, r.report.clampedLow);
    // And a huge stiffening one saturates at the ceiling; clamping happens after each stroke, so
    // a later softening stroke starts from the ceiling.
    strokes = {{Vec3(0.05, 0, 0), 0.02, 1e6, BrushScale::Peak}, {Vec3(0.05, 0, 0), 0.02, -0.5, BrushScale::Peak}};
    r = bakeStiffnessPaint(*b.mesh, b.skeleton, strokes, p);
    EXPECT_GT(r.report.clampedHigh, 0u);
    for (size_t i = 0; i < b.mesh->vertexCount(); ++i) {
        const double v = (b.mesh->positions()[i] - strokes[0].center).norm();
        if (r.weights[i] == 1.0 || v >= 0.02) continue;
        const double k = poly6Kernel(v, 0.02) / poly6Kernel(0, 0.02);
        const double afterFirst = std::min(3.0, 1.0 + 1e6 * k);
        EXPECT_NEAR(r.weights[i], std::max(0.05, afterFirst - 0.5 * k), 1e-12) << "node " << i;
    }
}

TEST(StiffnessPaint, BadStrokesAndParametersAreRejected) {
    EXPECT_EQ(strokeError({Vec3::Zero(), 0.01, 1.0, BrushScale::Peak}), "no error");
    EXPECT_EQ(strokeError({Vec3(0, NAN, 0), 0.01, 1.0, BrushScale::Peak}),
              "vessel: stroke 4: center has a non-finite coordinate");
    EXPECT_EQ(strokeError({Vec3::Zero(), 0.0, 1.0, BrushScale::Peak}),
              "vessel: stroke 4: radius is 0.000000 m (must be in [1e-6, 1e3] m)");
    EXPECT_THAT(strokeError({Vec3::Zero(), -1.0, 1.0, BrushScale::Peak}), HasSubstr("radius"));
    EXPECT_THAT(strokeError({Vec3::Zero(), NAN, 1.0, BrushScale::Peak}), HasSubstr("radius"));
    EXPECT_THAT(strokeError({Vec3::Zero(), 1e-40, 1.0, BrushScale::Peak}), HasSubstr("radius"));
    EXPECT_THAT(strokeError({Vec3::Zero(), 2e3, 1.0, BrushScale::Peak}), HasSubstr("radius"));
    EXPECT_EQ(strokeError({Vec3::Zero(), 1e-6, 1.0, BrushScale::Kernel}), "no error");
    EXPECT_THAT(strokeError({Vec3::Zero(), 0.01, INFINITY, BrushScale::Peak}),
                HasSubstr("stroke 4: amplitude is inf (must be finite)"));
    EXPECT_EQ(strokeError({Vec3::Zero(), 1e-6, 1e300, BrushScale::Kernel}),
              "vessel: stroke 4: amplitude × kernel at the centre is not finite");
    EXPECT_EQ(strokeError({Vec3::Zero(), 1e-6, 1e300, BrushScale::Peak}), "no error"); // clamped later

    Bar b = makeBar(4);
    auto paramError = [&](PaintParams p) -> std::string {
        try {
            bakeStiffnessPaint(*b.mesh, b.skeleton, {}, p);
        } catch (const std::invalid_argument& e) {
            return e.what();
        }
        return "no error";
    };
    PaintParams p;
    EXPECT_EQ(paramError(p), "no error");
    p.minWeight = 0;
    EXPECT_THAT(paramError(p), HasSubstr("PaintParams::minWeight is 0.000000 (must be finite and > 0"));
    p = {};
    p.maxWeight = 1e-4;
    EXPECT_THAT(paramError(p), HasSubstr("PaintParams::maxWeight"));
    p = {};
    p.baseWeight = NAN;
    EXPECT_THAT(paramError(p), HasSubstr("PaintParams::baseWeight"));
    // A stroke list with one bad stroke names it and paints nothing.
    std::vector<BrushStroke> strokes = {{Vec3(0.05, 0, 0), 0.02, 1.0, BrushScale::Peak},
                                        {Vec3(0.05, 0, 0), 0.02, NAN, BrushScale::Peak}};
    try {
        bakeStiffnessPaint(*b.mesh, b.skeleton, strokes);
        FAIL() << "no error";
    } catch (const std::invalid_argument& e) {
        EXPECT_THAT(e.what(), HasSubstr("sim::bakeStiffnessPaint(): stroke 1: amplitude is nan"));
    }
    // Mismatched sizes in the low-level call.
    const SkeletonNodeMap map = mapNodesToSkeleton(*b.mesh, b.skeleton);
    std::vector<double> w(3, 1.0);
    EXPECT_THROW(applyBrushStroke(b.mesh->positions(), b.skeleton, map, strokes[0], {}, w), std::invalid_argument);
}

namespace {

/// The nodes a stroke selects through the skeleton (independently of applyBrushStroke).
std::set<int32_t> selectedBy(const Bar& b, const SkeletonNodeMap& map, const BrushStroke& s) {
    std::set<int32_t> out;
    for (size_t j = 0; j < b.skeleton.nodes.size(); ++j)
        if ((b.skeleton.nodes[j] - s.center).norm() < s.radius)
            for (int32_t q = map.start[j]; q < map.start[j + 1]; ++q)
                out.insert(map.members[q]);
    return out;
}

/// Peak-normalised eq. 4.28: (1 − v²/h²)³, in long double.
long double peakFactor(long double v, long double h) {
    return referenceKernel(v, h) / referenceKernel(0.0L, h);
}

/// Neighbours straight from the tets (brute force), for checking nodeNeighbours.
std::vector<std::set<int32_t>> bruteNeighbours(const TetMesh& m) {
    std::vector<std::set<int32_t>> nb(m.vertexCount());
    for (const Tet& t : m.tets())
        for (int a = 0; a < 4; ++a)
            for (int c = 0; c < 4; ++c)
                if (a != c) nb[t[a]].insert(t[c]);
    return nb;
}

} // namespace

TEST(StiffnessPaint, SubtractIsAddOfTheNegatedAmplitude) {
    Bar b = makeBar(10);
    BrushStroke add{Vec3(0.05, 0.002, 0), 0.02, -0.7, BrushScale::Peak};
    BrushStroke sub = add;
    sub.amplitude = 0.7;
    sub.mode = BrushMode::Subtract;
    EXPECT_EQ(bakeStiffnessPaint(*b.mesh, b.skeleton, {add}).weights,
              bakeStiffnessPaint(*b.mesh, b.skeleton, {sub}).weights);
}

TEST(StiffnessPaint, MixMovesTowardsTheTargetByTheKernelAndNeverOvershoots) {
    Bar b = makeBar(10);
    const auto& x = b.mesh->positions();
    PaintParams p;
    p.baseWeight = 2.0;
    BrushStroke mix{Vec3(0.05, 0.001, -0.002), 0.025, 0.8, BrushScale::Peak, BrushMode::Mix, 5.0};
    const StiffnessPaintResult r = bakeStiffnessPaint(*b.mesh, b.skeleton, {mix}, p);
    const std::set<int32_t> sel = selectedBy(b, r.map, mix);
    ASSERT_GT(sel.size(), 10u);
    for (size_t i = 0; i < x.size(); ++i) {
        long double expected = 2.0L;
        if (sel.count(static_cast<int32_t>(i))) {
            const long double t = std::min(1.0L, 0.8L * peakFactor((x[i] - mix.center).norm(), mix.radius));
            expected += t * (5.0L - 2.0L);
        }
        EXPECT_NEAR(r.weights[i], static_cast<double>(expected), 1e-12 * static_cast<double>(expected)) << i;
        EXPECT_LE(r.weights[i], 5.0) << "overshoot at node " << i;
    }
    // full strength at the centre reaches the target there; repeated strokes converge to it
    mix.amplitude = 1.0;
    const StiffnessPaintResult many = bakeStiffnessPaint(*b.mesh, b.skeleton, std::vector<BrushStroke>(200, mix), p);
    for (int32_t i : sel) {
        // n strokes of factor t leave (1 − t)ⁿ of the distance to the target
        const long double t = peakFactor((x[i] - mix.center).norm(), mix.radius);
        const long double expected = 5.0L - 3.0L * std::pow(1.0L - t, 200.0L);
        EXPECT_NEAR(many.weights[i], static_cast<double>(expected), 1e-10) << i;
        EXPECT_LE(many.weights[i], 5.0) << i;
    }
    const auto centre = std::min_element(x.begin(), x.end(), [&](const Vec3& a, const Vec3& c) {
        return (a - mix.center).norm() < (c - mix.center).norm();
    });
    BrushStroke onNode = mix;
    onNode.center = *centre;
    EXPECT_EQ(bakeStiffnessPaint(*b.mesh, b.skeleton, {onNode}, p).weights[centre - x.begin()], 5.0)
        << "one full-strength stroke reaches the target at its centre";
}

TEST(StiffnessPaint, SmoothBlendsTowardsTheNeighbourMeanOfTheWeightsBeforeTheStroke) {
    Bar b = makeBar(10);
    const auto& x = b.mesh->positions();
    const NodeNeighbours nb = nodeNeighbours(*b.mesh);
    const auto brute = bruteNeighbours(*b.mesh);
    ASSERT_EQ(nb.nodeCount(), x.size());
    for (size_t i = 0; i < x.size(); ++i)
        ASSERT_EQ(std::set<int32_t>(nb.members.begin() + nb.start[i], nb.members.begin() + nb.start[i + 1]), brute[i])
            << "neighbours of node " << i;
    // a sharp bump, then one smoothing stroke over it
    const BrushStroke bump{Vec3(0.05, 0, 0), 0.01, 6.0, BrushScale::Peak};
    const BrushStroke smooth{Vec3(0.05, 0, 0), 0.03, 0.6, BrushScale::Peak, BrushMode::Smooth};
    const StiffnessPaintResult before = bakeStiffnessPaint(*b.mesh, b.skeleton, {bump});
    const StiffnessPaintResult after = bakeStiffnessPaint(*b.mesh, b.skeleton, {bump, smooth});
    const std::set<int32_t> sel = selectedBy(b, after.map, smooth);
    for (size_t i = 0; i < x.size(); ++i) {
        long double expected = before.weights[i];
        if (sel.count(static_cast<int32_t>(i))) {
            long double mean = 0;
            for (int32_t q : brute[i])
                mean += before.weights[q];
            mean /= brute[i].size();
            const long double t = std::min(1.0L, 0.6L * peakFactor((x[i] - smooth.center).norm(), smooth.radius));
            expected += t * (mean - expected);
        }
        EXPECT_NEAR(after.weights[i], static_cast<double>(expected), 1e-12 * static_cast<double>(expected)) << i;
    }
    // smoothing lowers the roughness Σ over edges of (w_a − w_b)²
    auto roughness = [&](const std::vector<double>& w) {
        double r = 0;
        for (size_t i = 0; i < x.size(); ++i)
            for (int32_t q : brute[i])
                r += (w[i] - w[q]) * (w[i] - w[q]);
        return r;
    };
    EXPECT_LT(roughness(after.weights), 0.8 * roughness(before.weights));
    EXPECT_EQ(bakeStiffnessPaint(*b.mesh, b.skeleton, {bump, smooth}).weights, after.weights) << "repeatable";
}

TEST(StiffnessPaint, BadMixAndSmoothStrokesAreRefusedAndChangeNothing) {
    BrushStroke s{Vec3(0.05, 0, 0), 0.02, 0.5, BrushScale::Peak, BrushMode::Mix, 0.0};
    EXPECT_THAT(strokeError(s), HasSubstr("vessel: stroke 4: target is 0"));
    s.target = NAN;
    EXPECT_THAT(strokeError(s), HasSubstr("target is nan"));
    s.target = 2;
    s.amplitude = -0.1;
    EXPECT_THAT(strokeError(s), HasSubstr("a mix or smooth strength must be >= 0"));
    s.mode = BrushMode::Smooth;
    EXPECT_THAT(strokeError(s), HasSubstr("a mix or smooth strength must be >= 0"));
    s.mode = static_cast<BrushMode>(9);
    s.amplitude = 1;
    EXPECT_THAT(strokeError(s), HasSubstr("mode is not a BrushMode value"));
    // smoothing without the mesh's neighbours: refused, weights as they were
    Bar b = makeBar(8);
    const SkeletonNodeMap map = mapNodesToSkeleton(*b.mesh, b.skeleton);
    std::vector<double> w(b.mesh->vertexCount(), 1.5);
    const auto w0 = w;
    s.mode = BrushMode::Smooth;
    try {
        applyBrushStroke(b.mesh->positions(), b.skeleton, map, s, {}, w);
        FAIL() << "no error";
    } catch (const std::invalid_argument& e) {
        EXPECT_THAT(e.what(), HasSubstr("smoothing needs the neighbours"));
    }
    EXPECT_EQ(w, w0);
}

// Polygon paint of a fascia [A Fig. 4.11]: strokes on the surface's vertices directly.
TEST(SurfacePaint, StrokesChangeTheVerticesInsideTheBrushByEq428AndItsModes) {
    const TriMesh tube = makeTubeSurface(Vec3(0, 0, 0), Vec3(0.1, 0, 0), 0.012, 24, 30);
    const auto& x = tube.positions();
    const BrushStroke add{Vec3(0.03, 0.012, 0.0), 0.02, 2.0, BrushScale::Peak};
    const BrushStroke soften{Vec3(0.07, -0.012, 0.0), 0.015, 0.5, BrushScale::Peak, BrushMode::Subtract};
    const BrushStroke mix{Vec3(0.05, 0.0, 0.012), 0.025, 0.7, BrushScale::Peak, BrushMode::Mix, 3.0};
    const BrushStroke smooth{Vec3(0.04, 0.0, 0.0), 0.03, 0.5, BrushScale::Peak, BrushMode::Smooth};
    StiffnessPaintReport report;
    const std::vector<double> w = bakeSurfacePaint(tube, {add, soften, mix, smooth}, {}, &report);
    ASSERT_EQ(w.size(), x.size());

    // independent evaluation in long double, stroke after stroke
    std::vector<std::set<int32_t>> nb(x.size());
    for (const Tri& t : tube.triangles())
        for (int a = 0; a < 3; ++a)
            for (int c = 0; c < 3; ++c)
                if (a != c) nb[t[a]].insert(t[c]);
    std::vector<long double> ref(x.size(), 1.0L);
    size_t k = 0;
    for (const BrushStroke& s : {add, soften, mix, smooth}) {
        const std::vector<long double> before = ref;
        size_t selected = 0;
        for (size_t i = 0; i < x.size(); ++i) {
            const long double v = (x[i] - s.center).norm();
            if (v >= s.radius) continue;
            ++selected;
            const long double f = peakFactor(v, s.radius);
            if (s.mode == BrushMode::Add) ref[i] += s.amplitude * f;
            if (s.mode == BrushMode::Subtract) ref[i] -= s.amplitude * f;
            if (s.mode == BrushMode::Mix) ref[i] += std::min(1.0L, s.amplitude * f) * (s.target - before[i]);
            if (s.mode == BrushMode::Smooth) {
                long double mean = 0;
                for (int32_t q : nb[i])
                    mean += before[q];
                mean /= nb[i].size();
                ref[i] += std::min(1.0L, s.amplitude * f) * (mean - before[i]);
            }
        }
        EXPECT_GT(selected, 5u) << "stroke " << k;
        EXPECT_EQ(report.strokeSelected[k], selected) << "stroke " << k;
        ++k;
    }
    size_t changed = 0;
    for (size_t i = 0; i < x.size(); ++i) {
        EXPECT_NEAR(w[i], static_cast<double>(ref[i]), 1e-12 * static_cast<double>(ref[i])) << "vertex " << i;
        changed += w[i] != 1.0;
    }
    EXPECT_GT(changed, 50u);
    EXPECT_EQ(bakeSurfacePaint(tube, {add, soften, mix, smooth}), w) << "repeatable";
}

TEST(SurfacePaint, BadStrokesAreRefusedAndChangeNothing) {
    const TriMesh tube = makeTubeSurface(Vec3(0, 0, 0), Vec3(0.1, 0, 0), 0.012, 12, 10);
    std::vector<double> w(tube.vertexCount(), 1.0);
    const auto w0 = w;
    BrushStroke s{Vec3(0.05, 0, 0), 0.02, 1.0, BrushScale::Peak, BrushMode::Smooth};
    EXPECT_THROW(applySurfaceBrushStroke(tube.positions(), s, {}, w), std::invalid_argument) << "no neighbours";
    s.mode = BrushMode::Add;
    s.radius = NAN;
    EXPECT_THROW(applySurfaceBrushStroke(tube.positions(), s, {}, w), std::invalid_argument);
    s.radius = 0.02;
    std::vector<double> shorter(3, 1.0);
    EXPECT_THROW(applySurfaceBrushStroke(tube.positions(), s, {}, shorter), std::invalid_argument);
    EXPECT_EQ(w, w0);
    s.center = Vec3(NAN, 0, 0);
    EXPECT_THROW(bakeSurfacePaint(tube, {s}), std::invalid_argument);
}
