#pragma once
/// Spatial hash broad phase [A §5.2, after Teschner et al. 2003]: axis-aligned boxes (one per
/// primitive, e.g. a surface triangle or its bounding sphere) are inserted into the cells of a
/// uniform grid they overlap; the cells are hashed into a table of buckets. A query returns the
/// primitives whose boxes overlap the query box, sorted and unique (hash collisions and cell
/// sharing are filtered out), so the result equals a brute-force box test.
///
/// Cost: build O(Σ cells per box) with a counting sort into the buckets (no per-bucket
/// allocation, reused between builds); query O(cells of the query box + candidates).
#include "sim/mesh/tri_mesh.hpp"

#include <array>
#include <cstdint>
#include <vector>

namespace viscera::sim {

struct Aabb {
    Vec3 lo = Vec3::Zero(), hi = Vec3::Zero(); ///< m, lo <= hi componentwise
    bool overlaps(const Aabb& o) const {
        return (lo.array() <= o.hi.array()).all() && (o.lo.array() <= hi.array()).all();
    }
};

class SpatialHash {
public:
    /// cellSize: grid spacing in metres (> 0; about the mean primitive size works well).
    /// tableSize: buckets (>= 1); 0 picks a prime near 2 × the number of boxes at build.
    explicit SpatialHash(double cellSize, size_t tableSize = 0);

    /// Inserts boxes[i] as primitive i (replaces what was built before). Boxes with non-finite
    /// bounds are skipped; a box covering more than 512 cells goes to a list that every query
    /// tests directly (so a few huge boxes cannot stall the build).
    void build(const std::vector<Aabb>& boxes);
    /// Primitives whose box overlaps q, ascending, into out (cleared first).
    void queryInto(const Aabb& q, std::vector<int32_t>& out) const;

    double cellSize() const { return m_cell; }
    size_t tableSize() const { return m_buckets.empty() ? 0 : m_buckets.size() - 1; }
    size_t entryCount() const { return m_entries.size(); }

private:
    std::array<int64_t, 3> cellOf(const Vec3& p) const;
    size_t bucketOf(int64_t i, int64_t j, int64_t k) const;
    double m_cell;
    size_t m_requestedTable;
    std::vector<Aabb> m_boxes;
    std::vector<uint32_t> m_buckets;       ///< bucket b holds m_entries[m_buckets[b], m_buckets[b+1])
    std::vector<int32_t> m_entries;        ///< primitive ids
    std::vector<int32_t> m_large;          ///< primitives too large for the grid
    mutable std::vector<uint32_t> m_stamp; ///< per primitive: last query that reported it
    mutable uint32_t m_query = 0;
};

} // namespace viscera::sim
