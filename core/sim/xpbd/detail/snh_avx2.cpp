// AVX2/FMA stable Neo-Hookean kernel: four tets per pack, one per lane. Compiled with
// -mavx2 -mfma (see sim/xpbd/CMakeLists.txt); selected at run time by snhAvx2Available(). This
// file includes nothing but the plain-data kernel header and the AVX2 helpers (avx2_ops.hpp), all
// with internal linkage, so no AVX2 code can leak into the rest of the library.
#include "sim/xpbd/detail/snh_kernel.hpp"

#if defined(__AVX2__) && defined(__FMA__)
#include "sim/xpbd/detail/avx2_ops.hpp"

namespace viscera::sim::detail {
namespace {

/// Solves K packs (4K tets of one colour, so no shared particle) with their instructions
/// interleaved: the square root and divisions of one pack overlap the arithmetic of the other.
template <int K> inline void solvePacks(SnhPack* P, double* xw, V h2inv, V gamma, bool first, bool keep) {
    const V one = _mm256_set1_pd(1.0), tiny = _mm256_set1_pd(1e-24);
    const V huge = _mm256_set1_pd(__builtin_huge_val());
    const V laneIndex = _mm256_set_pd(3, 2, 1, 0);
    const V signMask = _mm256_set1_pd(-0.0);
    V X[K][4], Y[K][4], Z[K][4], W[K][4], gFx[K][4], gFy[K][4], gFz[K][4], gHx[K][4], gHy[K][4], gHz[K][4];
    V sFF[K], sHH[K], sFH[K], cD2[K], J[K];
    for (int k = 0; k < K; ++k) {
        for (int s = 0; s < 4; ++s) {
            const int32_t* id = P[k].idx[s];
            toColumns(_mm256_load_pd(xw + 4 * static_cast<size_t>(id[0])),
                      _mm256_load_pd(xw + 4 * static_cast<size_t>(id[1])),
                      _mm256_load_pd(xw + 4 * static_cast<size_t>(id[2])),
                      _mm256_load_pd(xw + 4 * static_cast<size_t>(id[3])), X[k][s], Y[k][s], Z[k][s], W[k][s]);
        }
        const V d0x = sub(X[k][1], X[k][0]), d0y = sub(Y[k][1], Y[k][0]), d0z = sub(Z[k][1], Z[k][0]);
        const V d1x = sub(X[k][2], X[k][0]), d1y = sub(Y[k][2], Y[k][0]), d1z = sub(Z[k][2], Z[k][0]);
        const V d2x = sub(X[k][3], X[k][0]), d2y = sub(Y[k][3], Y[k][0]), d2z = sub(Z[k][3], Z[k][0]);
        V m[9];
        for (int e = 0; e < 9; ++e)
            m[e] = _mm256_load_pd(P[k].m[e]);
        // F = Ds Dm⁻¹, column c: Σ_j d_j m[3j + c].
        V Fx[3], Fy[3], Fz[3];
        for (int c = 0; c < 3; ++c) {
            Fx[c] = madd(d2x, m[6 + c], madd(d1x, m[3 + c], mul(d0x, m[c])));
            Fy[c] = madd(d2y, m[6 + c], madd(d1y, m[3 + c], mul(d0y, m[c])));
            Fz[c] = madd(d2z, m[6 + c], madd(d1z, m[3 + c], mul(d0z, m[c])));
        }
        V n2 = mul(Fx[0], Fx[0]);
        for (int c = 0; c < 3; ++c) {
            if (c > 0) n2 = madd(Fx[c], Fx[c], n2);
            n2 = madd(Fy[c], Fy[c], n2);
            n2 = madd(Fz[c], Fz[c], n2);
        }
        cD2[k] = n2;
        // Cofactor columns H_c = F_{c+1} × F_{c+2}.
        V Hx[3], Hy[3], Hz[3];
        for (int c = 0; c < 3; ++c) {
            const int a = (c + 1) % 3, b = (c + 2) % 3;
            Hx[c] = msub(Fy[a], Fz[b], mul(Fz[a], Fy[b]));
            Hy[c] = msub(Fz[a], Fx[b], mul(Fx[a], Fz[b]));
            Hz[c] = msub(Fx[a], Fy[b], mul(Fy[a], Fx[b]));
        }
        J[k] = madd(Fz[0], Hz[0], madd(Fy[0], Hy[0], mul(Fx[0], Hx[0])));
        // Gradients of vertex j+1: Σ_c F_c m[3j + c] and Σ_c H_c m[3j + c]; vertex 0: minus sum.
        for (int j = 0; j < 3; ++j) {
            const V a = m[3 * j], b = m[3 * j + 1], c = m[3 * j + 2];
            gFx[k][j + 1] = madd(Fx[2], c, madd(Fx[1], b, mul(Fx[0], a)));
            gFy[k][j + 1] = madd(Fy[2], c, madd(Fy[1], b, mul(Fy[0], a)));
            gFz[k][j + 1] = madd(Fz[2], c, madd(Fz[1], b, mul(Fz[0], a)));
            gHx[k][j + 1] = madd(Hx[2], c, madd(Hx[1], b, mul(Hx[0], a)));
            gHy[k][j + 1] = madd(Hy[2], c, madd(Hy[1], b, mul(Hy[0], a)));
            gHz[k][j + 1] = madd(Hz[2], c, madd(Hz[1], b, mul(Hz[0], a)));
        }
        gFx[k][0] = _mm256_xor_pd(add(add(gFx[k][1], gFx[k][2]), gFx[k][3]), signMask);
        gFy[k][0] = _mm256_xor_pd(add(add(gFy[k][1], gFy[k][2]), gFy[k][3]), signMask);
        gFz[k][0] = _mm256_xor_pd(add(add(gFz[k][1], gFz[k][2]), gFz[k][3]), signMask);
        gHx[k][0] = _mm256_xor_pd(add(add(gHx[k][1], gHx[k][2]), gHx[k][3]), signMask);
        gHy[k][0] = _mm256_xor_pd(add(add(gHy[k][1], gHy[k][2]), gHy[k][3]), signMask);
        gHz[k][0] = _mm256_xor_pd(add(add(gHz[k][1], gHz[k][2]), gHz[k][3]), signMask);
        V ff = _mm256_setzero_pd(), hh = ff, fh = ff;
        for (int s = 0; s < 4; ++s) {
            ff = madd(W[k][s], madd(gFz[k][s], gFz[k][s], madd(gFy[k][s], gFy[k][s], mul(gFx[k][s], gFx[k][s]))), ff);
            hh = madd(W[k][s], madd(gHz[k][s], gHz[k][s], madd(gHy[k][s], gHy[k][s], mul(gHx[k][s], gHx[k][s]))), hh);
            fh = madd(W[k][s], madd(gFz[k][s], gHz[k][s], madd(gFy[k][s], gHy[k][s], mul(gFx[k][s], gHx[k][s]))), fh);
        }
        sFF[k] = ff;
        sHH[k] = hh;
        sFH[k] = fh;
    }
    // 2×2 block [A eq. 4.43] in the unknowns (e, dH) with dD = |F| e, so that the deviatoric
    // gradient enters unnormalised:
    //   [ Σw|g_F|² + α̃_D |F|²   Σw g_F·g_H    ] [e ]   [ −|F|² − α̃_D λ_D |F| ]
    //   [ Σw g_F·g_H             Σw|g_H|² + α̃_H] [dH] = [ −C_H − α̃_H λ_H       ]
    // Masks: padding lanes, |F| ≈ 0 and a singular block move nothing.
    V cF[K], dH[K];
    for (int k = 0; k < K; ++k) {
        const V laneOk = _mm256_cmp_pd(laneIndex, _mm256_set1_pd(P[k].lanes), _CMP_LT_OQ);
        const V normOk = _mm256_cmp_pd(cD2[k], tiny, _CMP_GT_OQ);
        const V cD = _mm256_sqrt_pd(cD2[k]);
        const V lD = first ? _mm256_setzero_pd() : _mm256_load_pd(P[k].lamD);
        const V lH = first ? _mm256_setzero_pd() : _mm256_load_pd(P[k].lamH);
        const V tD = mul(_mm256_load_pd(P[k].alphaD), h2inv), tH = mul(_mm256_load_pd(P[k].alphaH), h2inv);
        const V a00 = madd(tD, cD2[k], sFF[k]);
        const V a11 = add(sHH[k], tH);
        const V a01 = sFH[k];
        const V det = msub(a00, a11, mul(a01, a01));
        const V detOk =
            _mm256_and_pd(_mm256_cmp_pd(det, _mm256_setzero_pd(), _CMP_GT_OQ), _mm256_cmp_pd(det, huge, _CMP_LT_OQ));
        const V ok = _mm256_and_pd(_mm256_and_pd(laneOk, normOk), detOk);
        const V invDet = _mm256_div_pd(one, _mm256_blendv_pd(one, det, ok));
        const V r0 = _mm256_xor_pd(madd(mul(tD, lD), cD, cD2[k]), signMask);
        const V r1 = nmadd(tH, lH, sub(gamma, J[k]));
        const V e = _mm256_and_pd(mul(msub(a11, r0, mul(a01, r1)), invDet), ok);
        dH[k] = _mm256_and_pd(mul(msub(a00, r1, mul(a01, r0)), invDet), ok);
        cF[k] = e;
        if (keep) {
            _mm256_store_pd(P[k].lamD, madd(e, cD, lD));
            _mm256_store_pd(P[k].lamH, add(lH, dH[k]));
        }
    }
    for (int k = 0; k < K; ++k)
        for (int s = 0; s < 4; ++s) {
            const V DX = mul(W[k][s], madd(dH[k], gHx[k][s], mul(cF[k], gFx[k][s])));
            const V DY = mul(W[k][s], madd(dH[k], gHy[k][s], mul(cF[k], gFy[k][s])));
            const V DZ = mul(W[k][s], madd(dH[k], gHz[k][s], mul(cF[k], gFz[k][s])));
            storeRows(xw, P[k].idx[s], add(X[k][s], DX), add(Y[k][s], DY), add(Z[k][s], DZ), W[k][s]);
        }
}

} // namespace

bool snhAvx2Available() {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
}

void snhSolveAvx2(SnhPack* packs, size_t count, const SnhParams& prm) {
    const V h2inv = _mm256_set1_pd(prm.h2inv), gamma = _mm256_set1_pd(prm.gamma);
    const bool first = prm.first != 0, keep = prm.keep != 0;
    size_t q = 0;
    for (; q + 2 <= count; q += 2) {
        // The particles of the next two packs: L2 → L1 while this pair computes.
        for (size_t n = q + 2; n < q + 4 && n < count; ++n)
            for (int s = 0; s < 4; ++s)
                for (int l = 0; l < 4; ++l)
                    _mm_prefetch(reinterpret_cast<const char*>(prm.xw + 4 * static_cast<size_t>(packs[n].idx[s][l])),
                                 _MM_HINT_T0);
        solvePacks<2>(packs + q, prm.xw, h2inv, gamma, first, keep);
    }
    if (q < count) solvePacks<1>(packs + q, prm.xw, h2inv, gamma, first, keep);
}

} // namespace viscera::sim::detail

#else

namespace viscera::sim::detail {

bool snhAvx2Available() {
    return false;
}
void snhSolveAvx2(SnhPack* packs, size_t count, const SnhParams& p) {
    snhSolveScalar(packs, count, p);
}

} // namespace viscera::sim::detail

#endif
