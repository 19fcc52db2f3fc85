#pragma once
/// What the UV transfer (uv_transfer.cpp) and the seam cut (seam_cut.cpp) share; private to
/// studio/bake.
#include "bake/uv_transfer.hpp"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <utility>

namespace viscera::bake::detail {

/// One key per undirected edge.
inline uint64_t edgeKey(int32_t a, int32_t b) {
    if (a > b) std::swap(a, b);
    return (uint64_t(uint32_t(a)) << 32) | uint32_t(b);
}

/// Sample points inside a triangle (barycentric): the centroid and three points halfway from it
/// to each corner's side, away from the edges (a triangle along a seam keeps them on its side).
inline const std::array<Eigen::Vector3d, 4> kInside = {
    Eigen::Vector3d(1.0 / 3, 1.0 / 3, 1.0 / 3), Eigen::Vector3d(0.5, 0.25, 0.25), Eigen::Vector3d(0.25, 0.5, 0.25),
    Eigen::Vector3d(0.25, 0.25, 0.5)};

/// Share of a triangle's longest edge by which an inside sample must be closer to another island
/// (or chart) than to its own for the triangle to lie over two.
inline constexpr double kStrayTolerance = 0.05;

/// Whether triangle p lies over two islands (`charts`: two charts), `own` being its own: an
/// inside sample is closer to another one than to `own` by more than kStrayTolerance of the
/// longest edge. Closer by less, both are as good a host: a point over the crease where two parts
/// meet, or off a ridge, is about as far from either.
bool overTwo(const UvSource& source, const std::array<Eigen::Vector3d, 3>& p, bool charts, int own);

} // namespace viscera::bake::detail
