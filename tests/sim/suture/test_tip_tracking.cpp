#include "sim/mesh/generators.hpp"
#include "sim/suture/tip_tracking.hpp"
#include "tracking_reference.hpp"

#include <gtest/gtest.h>

#include <numbers>
#include <random>

using namespace viscera::sim;
using viscera::sim::suture_testing::Visit;

namespace {

std::unique_ptr<TetMesh> jitteredBox(std::array<int, 3> cells, double jitter, uint32_t seed) {
    auto box = makeBoxTetMesh({Vec3::Zero(), Vec3(1.0, 0.8, 0.6), cells});
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-jitter, jitter);
    auto pos = box->positions();
    const double h = 0.6 / cells[2];
    for (Vec3& p : pos)
        p += h * Vec3(u(rng), u(rng), u(rng));
    auto m = TetMesh::fromArrays(std::move(pos), box->tets());
    m->requireLevel(3);
    return m;
}

/// Cells visited by the tracker with their parameter intervals.
std::vector<Visit> trackedVisits(const TipTracker& tr, const NeedleCurve& c, double a, double b, double minLength,
                                 int* edgeOrVertex) {
    const auto& x = tr.mesh().positions();
    std::vector<Crossing> cr;
    const int32_t start = tr.locate(x, c.point(a));
    tr.track(x, c, a, b, start, cr);
    std::vector<Visit> out;
    int32_t cell = start;
    double from = a;
    for (const Crossing& k : cr) {
        EXPECT_EQ(k.fromCell, cell);
        if (cell != kNone && k.alpha - from > minLength) out.push_back({cell, from, k.alpha});
        if (k.kind != CrossingKind::Face) ++*edgeOrVertex;
        // The recorded facet carries the crossing point.
        if (k.face != kNone) {
            const auto v = tr.mesh().halfFacetVertices(k.face);
            const Vec3 p = k.xi[0] * x[v[0]] + k.xi[1] * x[v[1]] + k.xi[2] * x[v[2]];
            EXPECT_LT((p - c.point(k.alpha)).norm(), 1e-9);
        }
        cell = k.toCell;
        from = k.alpha;
    }
    if (cell != kNone && b - from > minLength) out.push_back({cell, from, b});
    return out;
}

void expectSameCells(const std::vector<Visit>& got, const std::vector<Visit>& ref, const std::string& what) {
    if (got.size() != ref.size()) {
        std::string g, r;
        for (const Visit& v : got)
            g += " " + std::to_string(v.cell) + "[" + std::to_string(v.a) + "," + std::to_string(v.b) + "]";
        for (const Visit& v : ref)
            r += " " + std::to_string(v.cell) + "[" + std::to_string(v.a) + "," + std::to_string(v.b) + "]";
        ADD_FAILURE() << what << "\n got:" << g << "\n ref:" << r;
        return;
    }
    for (size_t i = 0; i < got.size(); ++i) {
        EXPECT_EQ(got[i].cell, ref[i].cell) << what << " visit " << i;
        EXPECT_NEAR(got[i].a, ref[i].a, 1e-9) << what << " visit " << i;
        EXPECT_NEAR(got[i].b, ref[i].b, 1e-9) << what << " visit " << i;
    }
}

Vec3 randomUnit(std::mt19937& rng) {
    std::normal_distribution<double> n;
    return Vec3(n(rng), n(rng), n(rng)).normalized();
}

} // namespace

// Random straight and arc paths through a jittered block of 5,184 tets (and partly outside it),
// plus paths built to pass exactly through mesh vertices and edges: the tracked cells equal those
// found by brute-force intersection with every tet.
TEST(TipTracking, MatchesBruteForceOnRandomPaths) {
    auto m = jitteredBox({12, 12, 6}, 0.2, 9);
    ASSERT_GT(m->tetCount(), 5000u);
    const TipTracker tr(*m);
    const auto& x = m->positions();
    const double minLen = 1e-7;
    std::mt19937 rng(17);
    std::uniform_real_distribution<double> u(0, 1);
    auto randomPoint = [&] { return Vec3(-0.2 + 1.4 * u(rng), -0.2 + 1.2 * u(rng), -0.2 + 1.0 * u(rng)); };
    int paths = 0, edgeOrVertex = 0, totalVisits = 0;
    for (int trial = 0; trial < 60; ++trial) {
        // Straight.
        const NeedleCurve s = NeedleCurve::straight(randomPoint(), randomUnit(rng));
        const auto ref = suture_testing::bruteForceVisits(*m, x, s, 0, 1.5, minLen);
        expectSameCells(trackedVisits(tr, s, 0, 1.5, minLen, &edgeOrVertex), ref, "straight " + std::to_string(trial));
        // Arc, up to one and a half turns.
        const Vec3 n = randomUnit(rng);
        Vec3 a = randomUnit(rng).cross(n).normalized();
        const double r = 0.15 + 0.5 * u(rng);
        const NeedleCurve c = NeedleCurve::arc(randomPoint(), a, n.cross(a), r);
        const double a0 = r * 2 * std::numbers::pi * u(rng);
        const auto refA = suture_testing::bruteForceVisits(*m, x, c, a0, a0 + 3 * std::numbers::pi * r, minLen);
        expectSameCells(trackedVisits(tr, c, a0, a0 + 3 * std::numbers::pi * r, minLen, &edgeOrVertex), refA,
                        "arc " + std::to_string(trial));
        paths += 2;
        totalVisits += static_cast<int>(ref.size() + refA.size());
    }
    RecordProperty("random_paths", paths);
    RecordProperty("visits", totalVisits);
    EXPECT_GT(totalVisits, 1000);
}

TEST(TipTracking, MatchesBruteForceThroughVerticesAndEdges) {
    auto m = jitteredBox({12, 12, 6}, 0.2, 4);
    ASSERT_GT(m->tetCount(), 5000u);
    const TipTracker tr(*m);
    const auto& x = m->positions();
    const double minLen = 1e-7;
    std::mt19937 rng(23);
    std::uniform_real_distribution<double> u(0, 1);
    int edgeOrVertex = 0;
    for (int trial = 0; trial < 80; ++trial) {
        // Through an interior vertex, or through a point of an interior edge.
        Vec3 target;
        if (trial % 2 == 0) {
            int32_t v;
            do
                v = static_cast<int32_t>(u(rng) * m->vertexCount());
            while (m->isBoundaryVertex(v));
            target = x[v];
        } else {
            int32_t e;
            do
                e = static_cast<int32_t>(u(rng) * m->edgeCount());
            while (m->isBoundaryEdge(e));
            const auto ev = m->edgeVertices(e);
            target = 0.5 * (x[ev[0]] + x[ev[1]]);
        }
        const Vec3 w = randomUnit(rng);
        const NeedleCurve s = NeedleCurve::straight(target - 0.4 * w, w);
        expectSameCells(trackedVisits(tr, s, 0, 0.9, minLen, &edgeOrVertex),
                        suture_testing::bruteForceVisits(*m, x, s, 0, 0.9, minLen),
                        "straight " + std::to_string(trial));
        // An arc through the same point: centre off the point, α = 0 at the point.
        const double r = 0.1 + 0.3 * u(rng);
        const Vec3 uu = randomUnit(rng);
        Vec3 vv = randomUnit(rng);
        vv = (vv - vv.dot(uu) * uu).normalized();
        const NeedleCurve c = NeedleCurve::arc(target - r * uu, uu, vv, r);
        expectSameCells(trackedVisits(tr, c, -1.2 * r, 1.5 * r, minLen, &edgeOrVertex),
                        suture_testing::bruteForceVisits(*m, x, c, -1.2 * r, 1.5 * r, minLen),
                        "arc " + std::to_string(trial));
    }
    RecordProperty("edge_or_vertex_crossings", edgeOrVertex);
    EXPECT_GE(edgeOrVertex, 100); // the constructed paths do cross through edges and vertices
}

TEST(TipTracking, StopsAtTheBoundaryAndNeedsLevel3) {
    auto box = makeBoxTetMesh({Vec3::Zero(), Vec3(1, 1, 1), {3, 3, 3}});
    EXPECT_THROW(TipTracker{*box}, std::logic_error);
    box->requireLevel(3);
    const TipTracker tr(*box);
    const NeedleCurve s = NeedleCurve::straight(Vec3(-0.5, 0.41, 0.37), Vec3(1, 0.01, 0.02));
    std::vector<Crossing> cr;
    TrackOptions opt;
    opt.stopAtBoundary = true;
    double stop = 0;
    const int32_t cell = tr.track(box->positions(), s, 0, 3, kNone, cr, opt, &stop);
    ASSERT_EQ(cr.size(), 1u);
    EXPECT_EQ(cr[0].fromCell, kNone);
    EXPECT_EQ(cell, cr[0].toCell);
    EXPECT_NEAR(stop, 0.5 / std::sqrt(1.0) * s.w.norm() / s.w.x(), 1e-9);
    EXPECT_TRUE(box->isBoundaryHalfFacet(cr[0].face));
    // Continue to the far side: it leaves through a boundary facet.
    cr.clear();
    const int32_t out = tr.track(box->positions(), s, stop, 3, cell, cr, opt, &stop);
    EXPECT_EQ(out, kNone);
    EXPECT_EQ(cr.back().toCell, kNone);
    EXPECT_TRUE(box->isBoundaryHalfFacet(cr.back().face));
}
