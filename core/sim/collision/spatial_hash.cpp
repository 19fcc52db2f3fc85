#include "sim/collision/spatial_hash.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace viscera::sim {

namespace {
/// Boxes covering more cells than this go to a list that every query scans.
constexpr double kMaxCellsPerBox = 512;

bool isLarge(const std::array<int64_t, 3>& lo, const std::array<int64_t, 3>& hi) {
    double cells = 1;
    for (int a = 0; a < 3; ++a)
        cells *= static_cast<double>(hi[a] - lo[a] + 1);
    return cells > kMaxCellsPerBox;
}

size_t nextPrime(size_t n) {
    if (n < 3) return 3;
    for (size_t c = n | 1;; c += 2) {
        bool prime = true;
        for (size_t d = 3; d * d <= c; d += 2)
            if (c % d == 0) {
                prime = false;
                break;
            }
        if (prime) return c;
    }
}
} // namespace

SpatialHash::SpatialHash(double cellSize, size_t tableSize) : m_cell(cellSize), m_requestedTable(tableSize) {
    if (!(cellSize > 0) || !std::isfinite(cellSize))
        throw std::invalid_argument("sim::SpatialHash: cell size must be > 0, got " + std::to_string(cellSize));
}

std::array<int64_t, 3> SpatialHash::cellOf(const Vec3& p) const {
    // Clamped far beyond any scene so that the integer conversion stays defined.
    auto c = [&](double v) { return static_cast<int64_t>(std::clamp(std::floor(v / m_cell), -1e12, 1e12)); };
    return {c(p.x()), c(p.y()), c(p.z())};
}

size_t SpatialHash::bucketOf(int64_t i, int64_t j, int64_t k) const {
    // The primes of Teschner et al.; unsigned arithmetic wraps deterministically.
    const uint64_t h = (static_cast<uint64_t>(i) * 73856093ull) ^ (static_cast<uint64_t>(j) * 19349663ull) ^
                       (static_cast<uint64_t>(k) * 83492791ull);
    return static_cast<size_t>(h % (m_buckets.size() - 1));
}

void SpatialHash::build(const std::vector<Aabb>& boxes) {
    m_boxes = boxes;
    const size_t table = m_requestedTable ? m_requestedTable : nextPrime(2 * boxes.size() + 1);
    m_buckets.assign(table + 1, 0);
    m_stamp.assign(boxes.size(), 0);
    m_query = 0;
    auto forCells = [&](const Aabb& b, auto&& f) {
        if (!b.lo.allFinite() || !b.hi.allFinite()) return;
        const auto lo = cellOf(b.lo);
        const auto hi = cellOf(b.hi);
        if (isLarge(lo, hi)) return;
        for (int64_t i = lo[0]; i <= hi[0]; ++i)
            for (int64_t j = lo[1]; j <= hi[1]; ++j)
                for (int64_t k = lo[2]; k <= hi[2]; ++k)
                    f(bucketOf(i, j, k));
    };
    // Counting sort: sizes, prefix sums, fill.
    for (const Aabb& b : boxes)
        forCells(b, [&](size_t h) { ++m_buckets[h + 1]; });
    for (size_t h = 1; h < m_buckets.size(); ++h)
        m_buckets[h] += m_buckets[h - 1];
    m_large.clear();
    for (size_t p = 0; p < boxes.size(); ++p)
        if (boxes[p].lo.allFinite() && boxes[p].hi.allFinite() && isLarge(cellOf(boxes[p].lo), cellOf(boxes[p].hi)))
            m_large.push_back(static_cast<int32_t>(p));
    m_entries.assign(m_buckets.back(), -1);
    std::vector<uint32_t> fill(m_buckets.begin(), m_buckets.end() - 1);
    for (size_t p = 0; p < boxes.size(); ++p)
        forCells(boxes[p], [&](size_t h) { m_entries[fill[h]++] = static_cast<int32_t>(p); });
}

void SpatialHash::queryInto(const Aabb& q, std::vector<int32_t>& out) const {
    out.clear();
    if (m_buckets.size() < 2 || !q.lo.allFinite() || !q.hi.allFinite()) return;
    if (++m_query == 0) {
        std::fill(m_stamp.begin(), m_stamp.end(), 0);
        m_query = 1;
    }
    const auto lo = cellOf(q.lo);
    const auto hi = cellOf(q.hi);
    double cells = 1;
    for (int a = 0; a < 3; ++a)
        cells *= static_cast<double>(hi[a] - lo[a] + 1);
    if (cells > static_cast<double>(m_boxes.size())) {
        // A query box larger than the whole set: a linear scan is cheaper and exact.
        for (size_t p = 0; p < m_boxes.size(); ++p)
            if (m_boxes[p].lo.allFinite() && m_boxes[p].hi.allFinite() && m_boxes[p].overlaps(q))
                out.push_back(static_cast<int32_t>(p));
        return;
    }
    for (int64_t i = lo[0]; i <= hi[0]; ++i)
        for (int64_t j = lo[1]; j <= hi[1]; ++j)
            for (int64_t k = lo[2]; k <= hi[2]; ++k) {
                const size_t h = bucketOf(i, j, k);
                for (uint32_t e = m_buckets[h]; e < m_buckets[h + 1]; ++e) {
                    const int32_t p = m_entries[e];
                    if (m_stamp[p] == m_query) continue;
                    m_stamp[p] = m_query;
                    if (m_boxes[p].overlaps(q)) out.push_back(p);
                }
            }
    for (int32_t p : m_large)
        if (m_boxes[p].overlaps(q)) out.push_back(p);
    std::sort(out.begin(), out.end());
}

} // namespace viscera::sim
