#pragma once
/// AVX2/FMA helpers shared by the kernels built with -mavx2 -mfma (snh_avx2.cpp, membrane_avx2.cpp;
/// private to sim/xpbd). Include only from those files: everything here has internal linkage
/// (an anonymous namespace), so no AVX2 code can be merged into a copy the rest of the library
/// calls.
#if defined(__AVX2__) && defined(__FMA__)
#include <immintrin.h>

#include <cstddef>
#include <cstdint>

namespace viscera::sim::detail {
namespace {

using V = __m256d;

inline V add(V a, V b) {
    return _mm256_add_pd(a, b);
}
inline V sub(V a, V b) {
    return _mm256_sub_pd(a, b);
}
inline V mul(V a, V b) {
    return _mm256_mul_pd(a, b);
}
inline V madd(V a, V b, V c) {
    return _mm256_fmadd_pd(a, b, c);
} // a·b + c
inline V msub(V a, V b, V c) {
    return _mm256_fmsub_pd(a, b, c);
} // a·b − c
inline V nmadd(V a, V b, V c) {
    return _mm256_fnmadd_pd(a, b, c);
} // c − a·b

/// Rows r0..r3 (x, y, z, w of four particles) to columns X, Y, Z, W (one lane per particle).
inline void toColumns(V r0, V r1, V r2, V r3, V& X, V& Y, V& Z, V& W) {
    const V t0 = _mm256_unpacklo_pd(r0, r1), t1 = _mm256_unpackhi_pd(r0, r1);
    const V t2 = _mm256_unpacklo_pd(r2, r3), t3 = _mm256_unpackhi_pd(r2, r3);
    X = _mm256_permute2f128_pd(t0, t2, 0x20);
    Y = _mm256_permute2f128_pd(t1, t3, 0x20);
    Z = _mm256_permute2f128_pd(t0, t2, 0x31);
    W = _mm256_permute2f128_pd(t1, t3, 0x31);
}

/// Columns X, Y, Z, W back to the rows of the four lanes' particles, stored in lane order
/// 3, 2, 1, 0: a padding lane repeats the particle of lane 0 with its old value, and lane 0's
/// store comes last.
inline void storeRows(double* xw, const int32_t* idx, V X, V Y, V Z, V W) {
    const V t0 = _mm256_unpacklo_pd(X, Y), t1 = _mm256_unpackhi_pd(X, Y);
    const V t2 = _mm256_unpacklo_pd(Z, W), t3 = _mm256_unpackhi_pd(Z, W);
    _mm256_store_pd(xw + 4 * static_cast<size_t>(idx[3]), _mm256_permute2f128_pd(t1, t3, 0x31));
    _mm256_store_pd(xw + 4 * static_cast<size_t>(idx[2]), _mm256_permute2f128_pd(t0, t2, 0x31));
    _mm256_store_pd(xw + 4 * static_cast<size_t>(idx[1]), _mm256_permute2f128_pd(t1, t3, 0x20));
    _mm256_store_pd(xw + 4 * static_cast<size_t>(idx[0]), _mm256_permute2f128_pd(t0, t2, 0x20));
}

} // namespace
} // namespace viscera::sim::detail

#endif
