#pragma once
/// The random draws of the texture generator (internal): std::mt19937_64 streams seeded through
/// SplitMix64, and one fixed mapping from 64-bit integers to [0, 1), so that a seed gives the same
/// textures on every platform (std::uniform_real_distribution's output is implementation-defined).
#include <cstdint>
#include <random>

namespace viscera::bake::detail {

/// SplitMix64's finalizer: spreads a seed (or seed ^ index) over all 64 bits.
inline uint64_t splitmix64(uint64_t x) {
    x += 0x9e3779b97f4a7c15ull;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
    return x ^ (x >> 31);
}

/// [0, 1) from the top 53 bits of one draw.
inline double uniform01(std::mt19937_64& rng) {
    return static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

} // namespace viscera::bake::detail
