#include "sim/xpbd/detail/snh_kernel.hpp"

#include <cmath>

namespace viscera::sim::detail {

void snhSolveScalar(SnhPack* packs, size_t count, const SnhParams& prm) {
    double* const xw = prm.xw;
    for (size_t q = 0; q < count; ++q) {
        SnhPack& P = packs[q];
        for (int l = 0; l < P.lanes; ++l) {
            double* v[4];
            double w[4];
            for (int s = 0; s < 4; ++s) {
                v[s] = xw + 4 * static_cast<size_t>(P.idx[s][l]);
                w[s] = v[s][3];
            }
            double d[3][3]; // d[k][r]: edge k (vertex k+1 − vertex 0), component r
            for (int k = 0; k < 3; ++k)
                for (int r = 0; r < 3; ++r)
                    d[k][r] = v[k + 1][r] - v[0][r];
            double M[3][3];
            for (int j = 0; j < 3; ++j)
                for (int c = 0; c < 3; ++c)
                    M[j][c] = P.m[3 * j + c][l];
            double F[3][3]; // F[c][r]: column c
            double cD2 = 0;
            for (int c = 0; c < 3; ++c)
                for (int r = 0; r < 3; ++r) {
                    F[c][r] = d[0][r] * M[0][c] + d[1][r] * M[1][c] + d[2][r] * M[2][c];
                    cD2 += F[c][r] * F[c][r];
                }
            double lD = prm.first ? 0.0 : P.lamD[l];
            double lH = prm.first ? 0.0 : P.lamH[l];
            if (prm.keep) {
                P.lamD[l] = lD;
                P.lamH[l] = lH;
            }
            if (!(cD2 > 1e-24)) continue;
            const double cD = std::sqrt(cD2);
            double H[3][3]; // cofactor columns: H_0 = F_1 × F_2, H_1 = F_2 × F_0, H_2 = F_0 × F_1
            for (int c = 0; c < 3; ++c) {
                const double* a = F[(c + 1) % 3];
                const double* b = F[(c + 2) % 3];
                H[c][0] = a[1] * b[2] - a[2] * b[1];
                H[c][1] = a[2] * b[0] - a[0] * b[2];
                H[c][2] = a[0] * b[1] - a[1] * b[0];
            }
            const double J = F[0][0] * H[0][0] + F[0][1] * H[0][1] + F[0][2] * H[0][2];
            const double cH = J - prm.gamma;
            // Gradients: vertex j+1 gets column j of (∂C/∂F) Dm⁻ᵀ; vertex 0 minus their sum.
            double gF[4][3], gH[4][3];
            for (int r = 0; r < 3; ++r) {
                gF[0][r] = 0;
                gH[0][r] = 0;
                for (int j = 0; j < 3; ++j) {
                    gF[j + 1][r] = F[0][r] * M[j][0] + F[1][r] * M[j][1] + F[2][r] * M[j][2];
                    gH[j + 1][r] = H[0][r] * M[j][0] + H[1][r] * M[j][1] + H[2][r] * M[j][2];
                    gF[0][r] -= gF[j + 1][r];
                    gH[0][r] -= gH[j + 1][r];
                }
            }
            double sFF = 0, sHH = 0, sFH = 0;
            for (int s = 0; s < 4; ++s) {
                sFF += w[s] * (gF[s][0] * gF[s][0] + gF[s][1] * gF[s][1] + gF[s][2] * gF[s][2]);
                sHH += w[s] * (gH[s][0] * gH[s][0] + gH[s][1] * gH[s][1] + gH[s][2] * gH[s][2]);
                sFH += w[s] * (gF[s][0] * gH[s][0] + gF[s][1] * gH[s][1] + gF[s][2] * gH[s][2]);
            }
            // 2×2 block [A eq. 4.43] in (e, dH) with dD = |F| e (see snh_avx2.cpp).
            const double tD = P.alphaD[l] * prm.h2inv, tH = P.alphaH[l] * prm.h2inv;
            const double a00 = sFF + tD * cD2, a11 = sHH + tH, a01 = sFH;
            const double r0 = -(cD2 + tD * lD * cD), r1 = -cH - tH * lH;
            const double det = a00 * a11 - a01 * a01;
            if (!(det > 0) || !std::isfinite(det)) continue;
            const double e = (a11 * r0 - a01 * r1) / det;
            const double dH = (a00 * r1 - a01 * r0) / det;
            if (prm.keep) {
                P.lamD[l] = lD + e * cD;
                P.lamH[l] = lH + dH;
            }
            const double cF = e;
            for (int s = 0; s < 4; ++s)
                for (int r = 0; r < 3; ++r)
                    v[s][r] += w[s] * (cF * gF[s][r] + dH * gH[s][r]);
        }
    }
}

} // namespace viscera::sim::detail
