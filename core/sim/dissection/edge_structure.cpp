#include "sim/dissection/edge_structure.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace viscera::sim {

template <size_t K>
EdgeStructure EdgeStructure::build(const std::vector<std::array<int32_t, K>>& prims, size_t vertexCount,
                                   const char* where, const char* primName) {
    const std::string w = std::string("sim::EdgeStructure::") + where + "(): ";
    if (prims.empty()) throw std::invalid_argument(w + "no " + primName);
    constexpr int kEdges = K == 3 ? 3 : 6;
    static constexpr int kPairs[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};
    static constexpr int kTriPairs[3][2] = {{0, 1}, {1, 2}, {2, 0}};
    for (size_t p = 0; p < prims.size(); ++p) {
        for (size_t k = 0; k < K; ++k) {
            const int32_t v = prims[p][k];
            if (v < 0 || static_cast<size_t>(v) >= vertexCount)
                throw std::invalid_argument(w + primName + " " + std::to_string(p) + " references vertex " +
                                            std::to_string(v) + " (" + std::to_string(vertexCount) + " vertices)");
            for (size_t j = 0; j < k; ++j)
                if (prims[p][j] == v)
                    throw std::invalid_argument(w + primName + " " + std::to_string(p) + " repeats vertex " +
                                                std::to_string(v));
        }
    }
    // (a, b, primitive, local edge) sorted by (a, b, primitive).
    struct Item {
        int32_t a, b, p, k;
    };
    std::vector<Item> items;
    items.reserve(prims.size() * kEdges);
    for (size_t p = 0; p < prims.size(); ++p)
        for (int k = 0; k < kEdges; ++k) {
            const int* pr = K == 3 ? kTriPairs[k] : kPairs[k];
            int32_t a = prims[p][pr[0]], b = prims[p][pr[1]];
            if (a > b) std::swap(a, b);
            items.push_back({a, b, static_cast<int32_t>(p), k});
        }
    std::sort(items.begin(), items.end(), [](const Item& x, const Item& y) {
        if (x.a != y.a) return x.a < y.a;
        if (x.b != y.b) return x.b < y.b;
        return x.p < y.p;
    });
    EdgeStructure s;
    s.m_vertexCount = vertexCount;
    s.m_edgesPerPrim = kEdges;
    s.m_primEdges.assign(prims.size() * kEdges, -1);
    s.m_edgePrimStart.push_back(0);
    for (size_t i = 0; i < items.size();) {
        size_t j = i;
        const int32_t e = static_cast<int32_t>(s.m_edges.size());
        s.m_edges.push_back({items[i].a, items[i].b});
        for (; j < items.size() && items[j].a == items[i].a && items[j].b == items[i].b; ++j) {
            s.m_edgePrims.push_back(items[j].p);
            s.m_primEdges[size_t(items[j].p) * kEdges + items[j].k] = e;
        }
        s.m_edgePrimStart.push_back(static_cast<uint32_t>(s.m_edgePrims.size()));
        i = j;
    }
    s.m_vertexEdgeStart.assign(vertexCount + 1, 0);
    for (const Edge& e : s.m_edges)
        ++s.m_vertexEdgeStart[e[0] + 1];
    for (size_t v = 0; v < vertexCount; ++v)
        s.m_vertexEdgeStart[v + 1] += s.m_vertexEdgeStart[v];
    s.reset();
    return s;
}

EdgeStructure EdgeStructure::fromTriangles(const std::vector<Tri>& triangles, size_t vertexCount) {
    return build<3>(triangles, vertexCount, "fromTriangles", "triangle");
}

EdgeStructure EdgeStructure::fromTets(const std::vector<Tet>& tets, size_t vertexCount) {
    return build<4>(tets, vertexCount, "fromTets", "tet");
}

int32_t EdgeStructure::findEdge(int32_t a, int32_t b) const {
    if (a > b) std::swap(a, b);
    if (a < 0 || static_cast<size_t>(b) >= m_vertexCount) return -1;
    const auto first = m_edges.begin() + m_vertexEdgeStart[a];
    const auto last = m_edges.begin() + m_vertexEdgeStart[a + 1];
    const auto it = std::lower_bound(first, last, b, [](const Edge& e, int32_t v) { return e[1] < v; });
    return it != last && (*it)[1] == b ? static_cast<int32_t>(it - m_edges.begin()) : -1;
}

bool EdgeStructure::isOrphaned(size_t e) const {
    for (int32_t p : primitivesOf(e))
        if (!isCut(p)) return false;
    return true;
}

bool EdgeStructure::dissect(size_t e, std::vector<int32_t>* newlyCut) {
    if (e >= m_edges.size())
        throw std::out_of_range("sim::EdgeStructure::dissect(): edge " + std::to_string(e) + " is out of range (" +
                                std::to_string(m_edges.size()) + " edges)");
    if (m_dissected[e]) return false;
    m_dissected[e] = 1;
    ++m_dissectedCount;
    for (int32_t p : primitivesOf(e)) {
        if (m_share[p] == m_edgesPerPrim) {
            ++m_cutCount;
            if (newlyCut) newlyCut->push_back(p);
        }
        --m_share[p];
    }
    return true;
}

void EdgeStructure::intactMaskInto(std::vector<uint8_t>& out) const {
    out.resize(m_share.size());
    for (size_t p = 0; p < m_share.size(); ++p)
        out[p] = m_share[p] == m_edgesPerPrim ? 1 : 0;
}

void EdgeStructure::reset() {
    m_share.assign(m_primEdges.size() / m_edgesPerPrim, m_edgesPerPrim);
    m_dissected.assign(m_edges.size(), 0);
    m_dissectedCount = m_cutCount = 0;
}

} // namespace viscera::sim
