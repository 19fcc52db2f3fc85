// Edge-based structure [A §5.3.1]: edges and their primitives against brute force, share counts.
#include "dissection_test_support.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <map>
#include <set>

using namespace viscera::sim;
using ::testing::HasSubstr;

namespace {

template <class Prims> void expectMatchesBruteForce(const EdgeStructure& E, const Prims& prims, int perPrim) {
    // Brute force: every vertex pair of every primitive.
    std::map<std::pair<int32_t, int32_t>, std::set<int32_t>> ref;
    for (size_t p = 0; p < prims.size(); ++p)
        for (int a = 0; a < perPrim; ++a)
            for (int b = a + 1; b < perPrim; ++b) {
                const int32_t u = std::min(prims[p][a], prims[p][b]), v = std::max(prims[p][a], prims[p][b]);
                ref[{u, v}].insert(int32_t(p));
            }
    ASSERT_EQ(E.edgeCount(), ref.size());
    size_t e = 0;
    for (const auto& [key, ps] : ref) {
        EXPECT_EQ(E.edge(e)[0], key.first);
        EXPECT_EQ(E.edge(e)[1], key.second);
        const auto span = E.primitivesOf(e);
        EXPECT_EQ(std::set<int32_t>(span.begin(), span.end()), ps);
        EXPECT_EQ(E.findEdge(key.second, key.first), int32_t(e));
        ++e;
    }
    for (size_t p = 0; p < prims.size(); ++p) {
        ASSERT_EQ(E.edgesOf(p).size(), size_t(perPrim == 3 ? 3 : 6));
        for (int32_t k : E.edgesOf(p)) {
            const auto span = E.primitivesOf(k);
            EXPECT_NE(std::find(span.begin(), span.end(), int32_t(p)), span.end());
        }
        EXPECT_EQ(E.shareCount(p), perPrim == 3 ? 3 : 6);
    }
}

} // namespace

TEST(EdgeStructure, SheetEdgesMatchBruteForce) {
    const TriMesh sheet = dissection_test::makeSheet(6, 4, 0.06, 0.04);
    const EdgeStructure E = EdgeStructure::fromTriangles(sheet.triangles(), sheet.vertexCount());
    expectMatchesBruteForce(E, sheet.triangles(), 3);
    // Planar grid: E = V + F − 1 (Euler, one boundary loop).
    EXPECT_EQ(E.edgeCount(), sheet.vertexCount() + sheet.triangleCount() - 1);
    EXPECT_EQ(E.initialShareCount(), 3);
}

TEST(EdgeStructure, TetEdgesMatchBruteForce) {
    BoxSpec spec;
    spec.cells = {3, 2, 2};
    const auto box = makeBoxTetMesh(spec);
    const EdgeStructure E = EdgeStructure::fromTets(box->tets(), box->vertexCount());
    expectMatchesBruteForce(E, box->tets(), 4);
    EXPECT_EQ(E.initialShareCount(), 6);
}

TEST(EdgeStructure, DissectingAnEdgeDecrementsEveryPrimitiveAroundIt) {
    // Two triangles sharing edge (1, 2).
    const std::vector<Tri> tris = {{0, 1, 2}, {1, 3, 2}};
    EdgeStructure E = EdgeStructure::fromTriangles(tris, 4);
    ASSERT_EQ(E.edgeCount(), 5u);
    const int32_t shared = E.findEdge(2, 1);
    ASSERT_GE(shared, 0);
    EXPECT_EQ(E.primitivesOf(shared).size(), 2u);
    std::vector<int32_t> cut;
    EXPECT_TRUE(E.dissect(shared, &cut));
    EXPECT_EQ(cut, (std::vector<int32_t>{0, 1}));
    EXPECT_EQ(E.shareCount(0), 2);
    EXPECT_EQ(E.shareCount(1), 2);
    EXPECT_TRUE(E.isCut(0) && E.isCut(1));
    EXPECT_FALSE(E.dissect(shared, &cut)); // already dissected: nothing changes
    EXPECT_EQ(E.shareCount(0), 2);
    // A boundary edge of triangle 0 only: no new cut, share count 1.
    cut.clear();
    EXPECT_TRUE(E.dissect(E.findEdge(0, 1), &cut));
    EXPECT_TRUE(cut.empty());
    EXPECT_EQ(E.shareCount(0), 1);
    EXPECT_EQ(E.shareCount(1), 2);
    EXPECT_EQ(E.dissectedEdgeCount(), 2u);
    EXPECT_EQ(E.cutPrimitiveCount(), 2u);
    EXPECT_TRUE(E.isOrphaned(shared));
    std::vector<uint8_t> mask;
    E.intactMaskInto(mask);
    EXPECT_EQ(mask, (std::vector<uint8_t>{0, 0}));
    E.reset();
    EXPECT_EQ(E.shareCount(0), 3);
    EXPECT_EQ(E.dissectedEdgeCount(), 0u);
}

TEST(EdgeStructure, DissectingEveryEdgeZeroesEveryShareCount) {
    BoxSpec spec;
    spec.cells = {2, 2, 1};
    const auto box = makeBoxTetMesh(spec);
    EdgeStructure E = EdgeStructure::fromTets(box->tets(), box->vertexCount());
    std::vector<int32_t> cut;
    for (size_t e = 0; e < E.edgeCount(); ++e)
        E.dissect(e, &cut);
    EXPECT_EQ(cut.size(), box->tetCount()); // each tet reported once
    for (size_t p = 0; p < E.primitiveCount(); ++p)
        EXPECT_EQ(E.shareCount(p), 0);
    for (size_t e = 0; e < E.edgeCount(); ++e)
        EXPECT_TRUE(E.isOrphaned(e));
    EXPECT_EQ(E.vertexCount(), box->vertexCount());
}

TEST(EdgeStructure, BadInputNamesTheElement) {
    auto msg = [](auto fn) {
        try {
            fn();
        } catch (const std::invalid_argument& e) {
            return std::string(e.what());
        }
        return std::string("no throw");
    };
    EXPECT_THAT(msg([] {
                    EdgeStructure::fromTriangles({{0, 1, 9}}, 3);
                }),
                HasSubstr("sim::EdgeStructure::fromTriangles(): triangle 0 references vertex 9 (3 vertices)"));
    EXPECT_THAT(msg([] {
                    EdgeStructure::fromTets({{0, 1, 2, 1}}, 4);
                }),
                HasSubstr("sim::EdgeStructure::fromTets(): tet 0 repeats vertex 1"));
    EXPECT_THAT(msg([] { EdgeStructure::fromTriangles({}, 3); }), HasSubstr("no triangle"));
    EdgeStructure E = EdgeStructure::fromTriangles({{0, 1, 2}}, 3);
    EXPECT_THROW(E.dissect(3), std::out_of_range);
    EXPECT_EQ(E.findEdge(0, 7), -1);
}
