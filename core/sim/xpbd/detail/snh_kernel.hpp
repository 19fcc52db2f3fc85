#pragma once
/// Stable Neo-Hookean tet kernel on packs of four tets (private to sim/xpbd).
///
/// Plain data only: this header is shared with snh_avx2.cpp, which is compiled with
/// -mavx2 -mfma, so it must not define inline functions or templates (they could be merged
/// with the AVX2 copies at link time and run on a CPU without AVX2).
///
/// One pack holds four tets of the same colour (no shared particle) in structure-of-arrays
/// form. Each tet carries C_D = |F|_F and C_H = det F − γ, solved as one 2×2 block
/// [A eq. 4.43–4.44]. Padding lanes (lane ≥ lanes) repeat lane 0 and move nothing.
#include <cstddef>
#include <cstdint>

namespace viscera::sim::detail {

struct alignas(64) SnhPack {
    int32_t idx[4][4]; ///< [vertex slot][lane]: particle index
    double m[9][4];    ///< Dm⁻¹ entry (3·row + col) per lane, 1/m
    double alphaD[4];  ///< deviatoric compliance 1/(μ V w), 1/(Pa·m³)
    double alphaH[4];  ///< hydrostatic compliance 1/(λ V w), 1/(Pa·m³)
    double lamD[4];    ///< multipliers, accumulated over the iterations of one substep
    double lamH[4];
    int32_t lanes; ///< valid lanes, 1..4
};

struct SnhParams {
    double* xw;   ///< particles: x, y, z (m) and inverse mass (1/kg), 4 doubles each, 32-byte aligned
    double h2inv; ///< 1/h², 1/s²
    double gamma; ///< 1 + μ/λ
    int first;    ///< 1: first iteration of a substep (multipliers start from 0)
    int keep;     ///< 1: store the multipliers (another iteration of the substep follows)
};

/// Portable scalar kernel.
void snhSolveScalar(SnhPack* packs, size_t count, const SnhParams& p);
/// AVX2/FMA kernel; only call when snhAvx2Available().
void snhSolveAvx2(SnhPack* packs, size_t count, const SnhParams& p);
/// True when the AVX2 kernel was compiled in and the CPU supports AVX2 and FMA.
bool snhAvx2Available();

} // namespace viscera::sim::detail
