// AVX2/FMA membrane kernel: four triangles per pack, one per lane. Compiled with -mavx2 -mfma
// (see sim/xpbd/CMakeLists.txt); selected at run time by membraneAvx2Available(). Like
// snh_avx2.cpp it includes only its plain-data header and the internal-linkage helpers of
// avx2_ops.hpp, so no AVX2 code leaks into the rest of the library.
#include "sim/xpbd/detail/membrane_kernel.hpp"

#if defined(__AVX2__) && defined(__FMA__)
#include "sim/xpbd/detail/avx2_ops.hpp"

namespace viscera::sim::detail {
namespace {

void solvePack(MembranePack& P, double* xw, V h2inv, bool first) {
    const V zero = _mm256_setzero_pd(), half = _mm256_set1_pd(0.5), huge = _mm256_set1_pd(__builtin_huge_val());
    const V sqrt2half = _mm256_set1_pd(0.5 * 1.4142135623730951);
    V X[3], Y[3], Z[3], W[3];
    for (int s = 0; s < 3; ++s) {
        const int32_t* id = P.idx[s];
        toColumns(_mm256_load_pd(xw + 4 * static_cast<size_t>(id[0])),
                  _mm256_load_pd(xw + 4 * static_cast<size_t>(id[1])),
                  _mm256_load_pd(xw + 4 * static_cast<size_t>(id[2])),
                  _mm256_load_pd(xw + 4 * static_cast<size_t>(id[3])), X[s], Y[s], Z[s], W[s]);
    }
    const V active = _mm256_cmp_pd(_mm256_load_pd(P.active), zero, _CMP_NEQ_OQ);
    const V M[2][2] = {{_mm256_load_pd(P.m[0]), _mm256_load_pd(P.m[1])},
                       {_mm256_load_pd(P.m[2]), _mm256_load_pd(P.m[3])}};
    const V t = mul(h2inv, _mm256_load_pd(P.invKA));
    static const int kEntry[3][2] = {{0, 0}, {1, 1}, {0, 1}};
    for (int c = 0; c < 3; ++c) {
        const int ci = kEntry[c][0], cj = kEntry[c][1];
        const V scale = c == 2 ? sqrt2half : half; // scale · ½ of the scalar path
        // F = Ds M, Ds = [x1 − x0, x2 − x0]; F[col] per coordinate.
        V F[2][3];
        const V d1[3] = {sub(X[1], X[0]), sub(Y[1], Y[0]), sub(Z[1], Z[0])};
        const V d2[3] = {sub(X[2], X[0]), sub(Y[2], Y[0]), sub(Z[2], Z[0])};
        for (int r = 0; r < 3; ++r) {
            F[0][r] = madd(d2[r], M[1][0], mul(d1[r], M[0][0]));
            F[1][r] = madd(d2[r], M[1][1], mul(d1[r], M[0][1]));
        }
        V dot = madd(F[ci][2], F[cj][2], madd(F[ci][1], F[cj][1], mul(F[ci][0], F[cj][0])));
        if (ci == cj) dot = sub(dot, _mm256_set1_pd(1.0));
        const V C = mul(scale, dot);
        V g[3][3];
        for (int r = 0; r < 3; ++r) {
            g[1][r] = mul(scale, madd(M[0][ci], F[cj][r], mul(M[0][cj], F[ci][r])));
            g[2][r] = mul(scale, madd(M[1][ci], F[cj][r], mul(M[1][cj], F[ci][r])));
            g[0][r] = _mm256_xor_pd(add(g[1][r], g[2][r]), _mm256_set1_pd(-0.0));
        }
        V den = t;
        for (int i = 0; i < 3; ++i)
            den = madd(W[i], madd(g[i][2], g[i][2], madd(g[i][1], g[i][1], mul(g[i][0], g[i][0]))), den);
        const V ok = _mm256_and_pd(
            active, _mm256_and_pd(_mm256_cmp_pd(den, zero, _CMP_GT_OQ), _mm256_cmp_pd(den, huge, _CMP_LT_OQ)));
        const V lam = first ? zero : _mm256_load_pd(P.lam[c]);
        const V num = _mm256_xor_pd(madd(t, lam, C), _mm256_set1_pd(-0.0)); // −C − α̃ λ
        const V d = _mm256_and_pd(_mm256_div_pd(num, _mm256_blendv_pd(_mm256_set1_pd(1.0), den, ok)), ok);
        _mm256_store_pd(P.lam[c], add(lam, d));
        for (int i = 0; i < 3; ++i) {
            const V wd = mul(W[i], d);
            X[i] = madd(wd, g[i][0], X[i]);
            Y[i] = madd(wd, g[i][1], Y[i]);
            Z[i] = madd(wd, g[i][2], Z[i]);
        }
    }
    for (int s = 0; s < 3; ++s)
        storeRows(xw, P.idx[s], X[s], Y[s], Z[s], W[s]);
}

} // namespace

bool membraneAvx2Available() {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
}

void membraneSolveAvx2(MembranePack* packs, size_t count, const MembraneParams& prm) {
    const V h2inv = _mm256_set1_pd(prm.h2inv);
    const bool first = prm.first != 0;
    for (size_t q = 0; q < count; ++q) {
        if (q + 1 < count)
            for (int s = 0; s < 3; ++s)
                for (int l = 0; l < 4; ++l)
                    _mm_prefetch(
                        reinterpret_cast<const char*>(prm.xw + 4 * static_cast<size_t>(packs[q + 1].idx[s][l])),
                        _MM_HINT_T0);
        solvePack(packs[q], prm.xw, h2inv, first);
    }
}

} // namespace viscera::sim::detail

#else

namespace viscera::sim::detail {

bool membraneAvx2Available() {
    return false;
}
void membraneSolveAvx2(MembranePack*, size_t, const MembraneParams&) {}

} // namespace viscera::sim::detail

#endif
