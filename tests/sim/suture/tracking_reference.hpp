#pragma once
// Brute-force reference for tip tracking: the parameter intervals in which a curve lies inside each
// tet, found by testing every tet independently of the adjacency.
#include "sim/mesh/tet_mesh.hpp"
#include "sim/suture/needle_curve.hpp"

#include <algorithm>
#include <vector>

namespace viscera::sim::suture_testing {

struct Visit {
    int32_t cell;
    double a, b;
};

inline std::vector<Visit> bruteForceVisits(const TetMesh& m, const std::vector<Vec3>& x, const NeedleCurve& c, double a,
                                           double b, double minLength) {
    std::vector<Visit> out;
    double roots[16];
    for (int32_t t = 0; t < static_cast<int32_t>(m.tetCount()); ++t) {
        std::vector<double> params = {a, b};
        Vec3 n[4];
        double d[4];
        for (int i = 0; i < 4; ++i) {
            const auto v = m.halfFacetVertices(4 * t + i);
            n[i] = (x[v[1]] - x[v[0]]).cross(x[v[2]] - x[v[0]]).normalized();
            d[i] = n[i].dot(x[v[0]]);
            const int k = c.planeCrossings(n[i], d[i], a, b, roots, 16);
            params.insert(params.end(), roots, roots + k);
        }
        std::sort(params.begin(), params.end());
        double start = 0;
        bool open = false;
        for (size_t k = 0; k + 1 < params.size(); ++k) {
            const double p0 = params[k], p1 = params[k + 1];
            bool inside = p1 > p0;
            const Vec3 mid = c.point(0.5 * (p0 + p1));
            for (int i = 0; i < 4 && inside; ++i)
                inside = n[i].dot(mid) - d[i] <= 0;
            if (inside && !open) {
                start = p0;
                open = true;
            } else if (!inside && open) {
                if (p0 - start > minLength) out.push_back({t, start, p0});
                open = false;
            }
        }
        if (open && b - start > minLength) out.push_back({t, start, b});
    }
    std::sort(out.begin(), out.end(), [](const Visit& p, const Visit& q) { return p.a < q.a; });
    return out;
}

} // namespace viscera::sim::suture_testing
