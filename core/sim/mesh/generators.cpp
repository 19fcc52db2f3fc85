#include "sim/mesh/generators.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace viscera::sim {

std::unique_ptr<TetMesh> makeBoxTetMesh(const BoxSpec& spec) {
    // Plain ints, not a structured binding: the lambda below captures them (clang 14 cannot
    // capture bindings).
    const int nx = spec.cells[0], ny = spec.cells[1], nz = spec.cells[2];
    if (nx <= 0 || ny <= 0 || nz <= 0)
        throw std::invalid_argument("sim::makeBoxTetMesh(): cell counts must be positive");
    if (!(spec.size.array() > 0).all() || !spec.size.allFinite() || !spec.origin.allFinite())
        throw std::invalid_argument("sim::makeBoxTetMesh(): size must be positive and finite");
    auto id = [&](int i, int j, int k) { return static_cast<int32_t>((k * (ny + 1) + j) * (nx + 1) + i); };
    std::vector<Vec3> pos;
    pos.reserve(static_cast<size_t>((nx + 1) * (ny + 1) * (nz + 1)));
    for (int k = 0; k <= nz; ++k)
        for (int j = 0; j <= ny; ++j)
            for (int i = 0; i <= nx; ++i)
                pos.push_back(spec.origin +
                              Vec3(spec.size.x() * i / nx, spec.size.y() * j / ny, spec.size.z() * k / nz));
    // Kuhn subdivision: 6 tets per cube along monotone paths from corner (0,0,0) to (1,1,1).
    static constexpr int kPerm[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    std::vector<Tet> tets;
    tets.reserve(static_cast<size_t>(6 * nx * ny * nz));
    for (int k = 0; k < nz; ++k)
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i)
                for (const auto& perm : kPerm) {
                    int c[3] = {0, 0, 0};
                    Tet t;
                    t[0] = id(i, j, k);
                    for (int s = 0; s < 3; ++s) {
                        c[perm[s]] = 1;
                        t[s + 1] = id(i + c[0], j + c[1], k + c[2]);
                    }
                    const Vec3 &a = pos[t[0]], &b = pos[t[1]], &cc = pos[t[2]], &d = pos[t[3]];
                    if ((b - a).dot((cc - a).cross(d - a)) < 0) std::swap(t[2], t[3]);
                    tets.push_back(t);
                }
    return TetMesh::fromArrays(std::move(pos), std::move(tets), "sim::makeBoxTetMesh()");
}

TriMesh makeEllipsoidSurface(const Vec3& center, const Vec3& radii, int slices, int stacks) {
    if (slices < 3 || stacks < 2)
        throw std::invalid_argument("sim::makeEllipsoidSurface(): needs slices >= 3 and stacks >= 2");
    std::vector<Vec3> pos;
    std::vector<Tri> tris;
    pos.push_back(center + Vec3(0, 0, radii.z())); // north pole
    for (int s = 1; s < stacks; ++s) {
        const double th = std::numbers::pi * s / stacks;
        for (int l = 0; l < slices; ++l) {
            const double ph = 2.0 * std::numbers::pi * l / slices;
            pos.push_back(center + Vec3(radii.x() * std::sin(th) * std::cos(ph),
                                        radii.y() * std::sin(th) * std::sin(ph), radii.z() * std::cos(th)));
        }
    }
    pos.push_back(center - Vec3(0, 0, radii.z())); // south pole
    const auto south = static_cast<int32_t>(pos.size() - 1);
    auto ring = [&](int s, int l) { return static_cast<int32_t>(1 + (s - 1) * slices + (l % slices)); };
    for (int l = 0; l < slices; ++l)
        tris.push_back({0, ring(1, l), ring(1, l + 1)});
    for (int s = 1; s + 1 < stacks; ++s)
        for (int l = 0; l < slices; ++l) {
            tris.push_back({ring(s, l), ring(s + 1, l), ring(s + 1, l + 1)});
            tris.push_back({ring(s, l), ring(s + 1, l + 1), ring(s, l + 1)});
        }
    for (int l = 0; l < slices; ++l)
        tris.push_back({south, ring(stacks - 1, l + 1), ring(stacks - 1, l)});
    return TriMesh::fromArrays(std::move(pos), std::move(tris), "sim::makeEllipsoidSurface()");
}

TriMesh makeLiverSurface(const Vec3& center, const Vec3& halfSize, double wedge, int slices, int stacks) {
    if (!(halfSize.array() > 0).all() || !(wedge > 0 && wedge <= 1))
        throw std::invalid_argument("sim::makeLiverSurface(): half sizes must be positive and wedge in (0, 1]");
    TriMesh unit = makeEllipsoidSurface(Vec3::Zero(), Vec3::Ones(), slices, stacks);
    std::vector<Vec3> pos = unit.positions();
    for (Vec3& p : pos) {
        const double u = 0.5 * (p.x() + 1.0);               // 0 at the thin end, 1 at the thick end
        const double thickness = wedge + (1.0 - wedge) * u; // z scale
        p = Vec3(halfSize.x() * p.x(), halfSize.y() * p.y() + 0.25 * halfSize.y() * p.x() * p.x(),
                 halfSize.z() * thickness * p.z());
        p += center;
    }
    return TriMesh::fromArrays(std::move(pos), unit.triangles(), "sim::makeLiverSurface()");
}

TriMesh makeTubeSurface(const Vec3& a, const Vec3& b, double radius, int slices, int rings) {
    const Vec3 axis = b - a;
    const double len = axis.norm();
    if (!(len > 0) || !(radius > 0) || slices < 3 || rings < 1)
        throw std::invalid_argument("sim::makeTubeSurface(): needs a != b, radius > 0, slices >= 3, rings >= 1");
    const Vec3 d = axis / len;
    const Vec3 helper = std::abs(d.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
    const Vec3 e1 = d.cross(helper).normalized();
    const Vec3 e2 = d.cross(e1);
    std::vector<Vec3> pos;
    std::vector<Tri> tris;
    for (int r = 0; r <= rings; ++r)
        for (int s = 0; s < slices; ++s) {
            const double ph = 2.0 * std::numbers::pi * s / slices;
            pos.push_back(a + axis * (double(r) / rings) + radius * (std::cos(ph) * e1 + std::sin(ph) * e2));
        }
    auto id = [&](int r, int s) { return static_cast<int32_t>(r * slices + (s % slices)); };
    // e1 x e2 = d, so increasing angle runs counter-clockwise seen from +d: this winding points out.
    for (int r = 0; r < rings; ++r)
        for (int s = 0; s < slices; ++s) {
            tris.push_back({id(r, s), id(r, s + 1), id(r + 1, s + 1)});
            tris.push_back({id(r, s), id(r + 1, s + 1), id(r + 1, s)});
        }
    const auto ca = static_cast<int32_t>(pos.size());
    pos.push_back(a);
    const auto cb = static_cast<int32_t>(pos.size());
    pos.push_back(b);
    for (int s = 0; s < slices; ++s) {
        tris.push_back({ca, id(0, s + 1), id(0, s)});
        tris.push_back({cb, id(rings, s), id(rings, s + 1)});
    }
    return TriMesh::fromArrays(std::move(pos), std::move(tris), "sim::makeTubeSurface()");
}

TriMesh makeBoxSurface(const Vec3& lo, const Vec3& hi) {
    std::vector<Vec3> pos;
    for (int k = 0; k < 8; ++k)
        pos.emplace_back(k & 1 ? hi.x() : lo.x(), k & 2 ? hi.y() : lo.y(), k & 4 ? hi.z() : lo.z());
    std::vector<Tri> tris = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                             {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
    return TriMesh::fromArrays(std::move(pos), std::move(tris), "sim::makeBoxSurface()");
}

} // namespace viscera::sim

namespace viscera::sim {

std::unique_ptr<TetMesh> makeHollowTubeTetMesh(const HollowTubeSpec& s) {
    const Vec3 axis = s.end - s.start;
    if (!(axis.norm() > 0) || !(s.innerRadius > 0) || !(s.outerRadius > s.innerRadius) || s.slices < 3 ||
        s.layers < 1 || s.rings < 1)
        throw std::invalid_argument("sim::makeHollowTubeTetMesh(): needs start != end, 0 < inner < outer radius, "
                                    "slices >= 3, layers >= 1, rings >= 1");
    const Vec3 w = axis.normalized();
    Vec3 a = std::abs(w.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
    const Vec3 u = (a - a.dot(w) * w).normalized(), v = w.cross(u);
    const int ns = s.slices, nl = s.layers + 1, nr = s.rings + 1;
    auto id = [&](int i, int j, int k) { return static_cast<int32_t>((k * nl + j) * ns + (i % ns)); };
    std::vector<Vec3> pos;
    pos.reserve(static_cast<size_t>(ns * nl * nr));
    for (int k = 0; k < nr; ++k)
        for (int j = 0; j < nl; ++j)
            for (int i = 0; i < ns; ++i) {
                const double th = 2.0 * std::numbers::pi * i / ns;
                const double r = s.innerRadius + (s.outerRadius - s.innerRadius) * j / s.layers;
                pos.push_back(s.start + axis * (double(k) / s.rings) + r * (std::cos(th) * u + std::sin(th) * v));
            }
    static constexpr int kPerm[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    std::vector<Tet> tets;
    for (int k = 0; k < s.rings; ++k)
        for (int j = 0; j < s.layers; ++j)
            for (int i = 0; i < ns; ++i)
                for (const auto& perm : kPerm) {
                    int c[3] = {0, 0, 0};
                    Tet t;
                    t[0] = id(i, j, k);
                    for (int q = 0; q < 3; ++q) {
                        c[perm[q]] = 1;
                        t[q + 1] = id(i + c[0], j + c[1], k + c[2]);
                    }
                    const Vec3 &p0 = pos[t[0]], &p1 = pos[t[1]], &p2 = pos[t[2]], &p3 = pos[t[3]];
                    if ((p1 - p0).dot((p2 - p0).cross(p3 - p0)) < 0) std::swap(t[2], t[3]);
                    tets.push_back(t);
                }
    return TetMesh::fromArrays(std::move(pos), std::move(tets), "sim::makeHollowTubeTetMesh()");
}

} // namespace viscera::sim
