#pragma once
/// Membrane (Green-strain) triangle kernel on packs of four triangles (private to sim/xpbd).
///
/// Plain data only, for the same reason as snh_kernel.hpp: this header is shared with
/// membrane_avx2.cpp, which is compiled with -mavx2 -mfma.
///
/// One pack holds four triangles of the same colour (no shared particle) in structure-of-arrays
/// form. Each triangle carries the three constraints ε00, ε11, √2 ε01 of its Green strain
/// (membrane.hpp), solved one after the other (Gauss–Seidel) with α̃ = h² / (k A) each. Padding
/// lanes (lane ≥ lanes) repeat lane 0 and move nothing; so do lanes whose triangle is cut
/// (active 0).
#include <cstddef>
#include <cstdint>

namespace viscera::sim::detail {

/// The lane arrays of doubles come first, so that each starts on a 32-byte boundary (aligned loads).
struct alignas(64) MembranePack {
    double m[4][4];    ///< Dm⁻¹ entries M00, M01, M10, M11 per lane, 1/m
    double invKA[4];   ///< 1/(k A) per lane, 1/N (times 1/h²: α̃)
    double lam[3][4];  ///< multipliers, accumulated over the iterations of one substep
    double active[4];  ///< 1: the triangle is solved; 0: cut or padding
    int32_t idx[3][4]; ///< [vertex slot][lane]: particle index
};

struct MembraneParams {
    double* xw;   ///< particles: x, y, z (m) and inverse mass (1/kg), 4 doubles each, 32-byte aligned
    double h2inv; ///< 1/h², 1/s²
    int first;    ///< 1: first iteration of a substep (multipliers start from 0)
};

/// AVX2/FMA kernel; only call when membraneAvx2Available(). Same equations, in the same order, as
/// the block's scalar path (results differ in the last bits: fused multiply-adds).
void membraneSolveAvx2(MembranePack* packs, size_t count, const MembraneParams& p);
/// True when the AVX2 kernel was compiled in and the CPU supports AVX2 and FMA.
bool membraneAvx2Available();

} // namespace viscera::sim::detail
