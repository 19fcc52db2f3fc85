#include "bake/sample_anatomy.hpp"

#include "sim/mesh/generators.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <numbers>

namespace viscera::bake {
namespace {

/// The tube without its end caps: triangles with every vertex on an end plane are dropped.
sim::TriMesh uncapped(const sim::TriMesh& tube, const sim::Vec3& a, const sim::Vec3& b, const char* name = "ureter") {
    const sim::Vec3 axis = (b - a).normalized();
    const double length = (b - a).norm(), eps = 1e-9;
    std::vector<sim::Tri> kept;
    for (const sim::Tri& t : tube.triangles()) {
        bool atA = true, atB = true;
        for (int32_t v : t) {
            const double s = (tube.positions()[v] - a).dot(axis);
            atA = atA && std::abs(s) < eps;
            atB = atB && std::abs(s - length) < eps;
        }
        if (!atA && !atB) kept.push_back(t);
    }
    return sim::TriMesh::fromArrays(tube.positions(), std::move(kept), name);
}

constexpr double kPi = std::numbers::pi;

/// A rectangle of the texture atlas: [x0, x1] × [y0, y1].
struct Rect {
    double x0, y0, x1, y1;
    Eigen::Vector2d at(double u, double v) const { return {x0 + u * (x1 - x0), y0 + v * (y1 - y0)}; }
};

/// Angle coordinates of a triangle's corners, unwrapped so that they lie within π of each other
/// and their mean within [−π, π): the seam falls on the edges between triangles on either side of
/// ±π. Corners with no angle (a pole, an axis point: `defined` false) take the mean of the others.
std::array<double, 3> unwrapped(std::array<double, 3> phi, const std::array<bool, 3>& defined) {
    int ref = -1;
    for (int k = 0; k < 3; ++k)
        if (defined[k] && ref < 0) ref = k;
    if (ref < 0) return {0, 0, 0};
    double sum = 0;
    int count = 0;
    for (int k = 0; k < 3; ++k) {
        if (!defined[k]) continue;
        while (phi[k] - phi[ref] > kPi)
            phi[k] -= 2 * kPi;
        while (phi[k] - phi[ref] < -kPi)
            phi[k] += 2 * kPi;
        sum += phi[k];
        ++count;
    }
    double mean = sum / count;
    const double shift = mean >= kPi ? -2 * kPi : mean < -kPi ? 2 * kPi : 0.0;
    mean += shift;
    for (int k = 0; k < 3; ++k)
        phi[k] = defined[k] ? phi[k] + shift : mean;
    return phi;
}

/// Latitude–longitude UVs of an ellipsoid part about its z axis, from its undeformed positions:
/// `islands` equal sectors of longitude, each its own island in rects[i] (u: longitude across the
/// sector, v: latitude), so the sector borders are seams between islands; with one island the
/// seam at longitude ±π lies inside it (its two sides are far apart in the atlas). Each pole is
/// one point of its island: the pole's fan is pinched in UV, as in any latitude–longitude map.
std::vector<CornerUv> latLongUv(const sim::TriMesh& undeformed, const sim::Vec3& centre, const sim::Vec3& radii,
                                const std::vector<Rect>& rects) {
    const int islands = int(rects.size());
    std::vector<CornerUv> uv;
    for (const sim::Tri& t : undeformed.triangles()) {
        std::array<double, 3> phi{}, theta{};
        std::array<bool, 3> defined{};
        for (int k = 0; k < 3; ++k) {
            const sim::Vec3 q = (undeformed.positions()[t[k]] - centre).cwiseQuotient(radii);
            theta[k] = std::acos(std::clamp(q.z(), -1.0, 1.0));
            defined[k] = std::hypot(q.x(), q.y()) > 1e-9;
            phi[k] = defined[k] ? std::atan2(q.y(), q.x()) : 0.0;
        }
        phi = unwrapped(phi, defined);
        const double mean = (phi[0] + phi[1] + phi[2]) / 3.0;
        const double sector = 2 * kPi / islands;
        const int i = std::clamp(int(std::floor((mean + kPi) / sector)), 0, islands - 1);
        CornerUv c;
        for (int k = 0; k < 3; ++k) {
            const double u = defined[k] ? (phi[k] + kPi - i * sector) / sector : 0.5;
            c[k] = rects[size_t(i)].at(u, theta[k] / kPi);
        }
        uv.push_back(c);
    }
    return uv;
}

/// UVs of a tube from a to b: the side unwrapped around the axis (u: angle, v: along; the seam at
/// angle ±π inside the island `side`), each end cap (triangles with every corner on an end plane)
/// projected along the axis into its own island.
std::vector<CornerUv> tubeUv(const sim::TriMesh& tube, const sim::Vec3& a, const sim::Vec3& b, double radius,
                             const Rect& side, const Rect& capA, const Rect& capB) {
    const sim::Vec3 axis = (b - a).normalized();
    const double length = (b - a).norm();
    const sim::Vec3 e1 = axis.cross(std::abs(axis.x()) < 0.9 ? sim::Vec3::UnitX() : sim::Vec3::UnitY()).normalized();
    const sim::Vec3 e2 = axis.cross(e1);
    std::vector<CornerUv> uv;
    for (const sim::Tri& t : tube.triangles()) {
        std::array<double, 3> phi{}, along{};
        std::array<bool, 3> defined{};
        std::array<sim::Vec3, 3> local{};
        bool atA = true, atB = true;
        for (int k = 0; k < 3; ++k) {
            const sim::Vec3 d = tube.positions()[t[k]] - a;
            along[k] = d.dot(axis) / length;
            local[k] = sim::Vec3(d.dot(e1), d.dot(e2), 0) / radius;
            defined[k] = local[k].norm() > 1e-9;
            phi[k] = defined[k] ? std::atan2(local[k].y(), local[k].x()) : 0.0;
            atA = atA && std::abs(along[k]) < 1e-9;
            atB = atB && std::abs(along[k] - 1) < 1e-9;
        }
        CornerUv c;
        if (atA || atB) {
            const Rect& r = atA ? capA : capB;
            for (int k = 0; k < 3; ++k)
                c[k] = r.at(0.5 + 0.5 * local[k].x(), 0.5 + 0.5 * (atA ? -1 : 1) * local[k].y());
        } else {
            phi = unwrapped(phi, defined);
            for (int k = 0; k < 3; ++k)
                c[k] = side.at((phi[k] + kPi) / (2 * kPi), along[k]);
        }
        uv.push_back(c);
    }
    return uv;
}

/// A surface made of parameter grids, welded where grids share points (to 0.01 µm); triangles
/// left with a repeated corner by the weld (a grid's pinched row: a pole) are dropped.
class GridSurface {
public:
    using Map = std::function<sim::Vec3(double, double)>;
    using UvMap = std::function<Eigen::Vector2d(double, double)>;

    /// ns × nt quads over (s, t) in [0, 1]², two triangles each, wound so that ∂/∂s × ∂/∂t is the
    /// front (the back when `flip`); corner UVs by `uv`.
    void add(int ns, int nt, const Map& point, const UvMap& uv, bool flip) {
        auto at = [&](int i, int j) { return std::pair{double(i) / ns, double(j) / nt}; };
        for (int i = 0; i < ns; ++i)
            for (int j = 0; j < nt; ++j) {
                const std::array<std::pair<double, double>, 4> q{at(i, j), at(i + 1, j), at(i + 1, j + 1),
                                                                 at(i, j + 1)};
                const std::array<std::array<int, 3>, 2> halves{{{0, 1, 2}, {0, 2, 3}}};
                for (const auto& h : halves) {
                    std::array<int, 3> c = h;
                    if (flip) std::swap(c[1], c[2]);
                    sim::Tri tri;
                    CornerUv cu;
                    for (int k = 0; k < 3; ++k) {
                        const auto [s, t] = q[size_t(c[k])];
                        tri[k] = vertex(point(s, t));
                        cu[k] = uv(s, t);
                    }
                    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2]) continue;
                    m_tris.push_back(tri);
                    m_uv.push_back(cu);
                }
            }
    }

    RemeshPart part(const std::string& name) {
        return {name, sim::TriMesh::fromArrays(std::move(m_pos), std::move(m_tris), name), CsgOp::Union,
                std::move(m_uv)};
    }

private:
    int32_t vertex(const sim::Vec3& p) {
        const std::array<long, 3> key{std::lround(p.x() * 1e8), std::lround(p.y() * 1e8), std::lround(p.z() * 1e8)};
        auto [it, added] = m_index.try_emplace(key, int32_t(m_pos.size()));
        if (added) m_pos.push_back(p);
        return it->second;
    }

    std::map<std::array<long, 3>, int32_t> m_index;
    std::vector<sim::Vec3> m_pos;
    std::vector<sim::Tri> m_tris;
    std::vector<CornerUv> m_uv;
};

/// The six faces of the unit cube of parameters (u, v, w), `n` cells along each, through `map`
/// (orientation-preserving: the faces come out facing outwards). UVs: the face w = 1 by (u, v) in
/// `outer`, w = 0 in `inner`, the four others each a quarter of `rims`.
void addMappedCube(GridSurface& g, const std::array<int, 3>& n, const std::function<sim::Vec3(const sim::Vec3&)>& map,
                   const Rect& outer, const Rect& inner, const Rect& rims) {
    int rim = 0;
    for (int a = 0; a < 3; ++a)
        for (int side = 0; side < 2; ++side) {
            const int b = (a + 1) % 3, c = (a + 2) % 3;
            auto point = [&, a, b, c, side](double s, double t) {
                sim::Vec3 q;
                q[a] = side;
                q[b] = s;
                q[c] = t;
                return map(q);
            };
            Rect r = rims;
            if (a == 2)
                r = side == 1 ? outer : inner;
            else {
                const double w = (rims.x1 - rims.x0) / 4;
                r = {rims.x0 + rim * w, rims.y0, rims.x0 + (rim + 1) * w - 0.005, rims.y1};
                ++rim;
            }
            // Face a = 2 is (u, v): keep u across the island for it; the others by (s, t).
            auto uv = [r, a](double s, double t) { return a == 2 ? r.at(t, s) : r.at(s, t); };
            g.add(n[size_t(b)], n[size_t(c)], point, uv, side == 0);
        }
}

double smoothstep(double e0, double e1, double x) {
    const double t = std::clamp((x - e0) / (e1 - e0), 0.0, 1.0);
    return t * t * (3 - 2 * t);
}

} // namespace

std::vector<RemeshPart> kidneyAnatomy(int slices) {
    // Cortex: the ellipsoid, dented on its medial side, one triangle near the upper pole removed.
    const sim::TriMesh ellipsoid =
        sim::makeEllipsoidSurface(sim::Vec3::Zero(), sim::Vec3(0.03, 0.055, 0.02), slices, slices / 2);
    std::vector<sim::Vec3> p = ellipsoid.positions();
    for (sim::Vec3& x : p)
        if (x.x() > 0) {
            const double g = std::exp(-(x.y() * x.y()) / (0.015 * 0.015) - (x.z() * x.z()) / (0.01 * 0.01));
            x.x() -= 0.07 * g;
        }
    std::vector<sim::Tri> tris = ellipsoid.triangles();
    size_t hole = 0;
    double best = 0;
    for (size_t t = 0; t < tris.size(); ++t) { // the triangle whose centroid is nearest (0, 40 mm, 8 mm)
        const sim::Vec3 c = (p[tris[t][0]] + p[tris[t][1]] + p[tris[t][2]]) / 3.0;
        const double score = -(c - sim::Vec3(0, 0.04, 0.008)).squaredNorm();
        if (t == 0 || score > best) {
            best = score;
            hole = t;
        }
    }
    // The texture atlas [issue 16 item 7]: the cortex one island (its seam inside it, along the
    // lateral meridian), the pelvis two (front and back: two seams between islands), the ureter
    // one (a seam along its length), the artery three (side and end caps).
    std::vector<CornerUv> cortexUv =
        latLongUv(ellipsoid, sim::Vec3::Zero(), sim::Vec3(0.03, 0.055, 0.02), {{0.02, 0.02, 0.58, 0.98}});
    cortexUv.erase(cortexUv.begin() + long(hole));
    tris.erase(tris.begin() + long(hole));
    std::vector<RemeshPart> parts;
    parts.push_back({"cortex", sim::TriMesh::fromArrays(std::move(p), std::move(tris), "cortex"), CsgOp::Union,
                     std::move(cortexUv)});
    const sim::Vec3 pc(0.012, 0, 0), pr(0.018, 0.014, 0.01);
    sim::TriMesh pelvis = sim::makeEllipsoidSurface(pc, pr, slices / 2, slices / 4);
    std::vector<CornerUv> pelvisUv = latLongUv(pelvis, pc, pr, {{0.62, 0.52, 0.79, 0.98}, {0.81, 0.52, 0.98, 0.98}});
    parts.push_back({"pelvis", std::move(pelvis), CsgOp::Union, std::move(pelvisUv)});
    const sim::Vec3 ua(0.022, -0.006, 0), ub(0.03, -0.09, -0.004);
    sim::TriMesh ureter = uncapped(sim::makeTubeSurface(ua, ub, 0.004, slices / 3, slices / 3), ua, ub);
    std::vector<CornerUv> ureterUv = tubeUv(ureter, ua, ub, 0.004, {0.62, 0.02, 0.79, 0.48}, {}, {});
    parts.push_back({"ureter", std::move(ureter), CsgOp::Union, std::move(ureterUv)});
    const sim::Vec3 aa(0.015, 0.008, 0.004), ab(0.06, 0.02, 0.01);
    sim::TriMesh artery = sim::makeTubeSurface(aa, ab, 0.003, slices / 4, slices / 8);
    std::vector<CornerUv> arteryUv =
        tubeUv(artery, aa, ab, 0.003, {0.81, 0.14, 0.98, 0.48}, {0.81, 0.02, 0.885, 0.12}, {0.905, 0.02, 0.98, 0.12});
    parts.push_back({"artery", std::move(artery), CsgOp::Union, std::move(arteryUv)});
    return parts;
}

std::vector<RemeshPart> hepatocysticAnatomy(int slices) {
    std::vector<RemeshPart> parts;
    // Liver: the right lobe's underside, a flattened ellipsoid; the triangles of its top (the bare
    // area, z above 70 mm) are missing, as in a surface cut from a scan.
    const sim::Vec3 lc(0, 0.01, 0.045), lr(0.09, 0.065, 0.03);
    const sim::TriMesh liverWhole = sim::makeEllipsoidSurface(lc, lr, slices, slices / 2);
    std::vector<CornerUv> liverUvWhole = latLongUv(liverWhole, lc, lr, {{0.02, 0.02, 0.58, 0.98}});
    std::vector<sim::Tri> liverTris;
    std::vector<CornerUv> liverUv;
    for (size_t t = 0; t < liverWhole.triangles().size(); ++t) {
        const sim::Tri& tri = liverWhole.triangles()[t];
        const auto& x = liverWhole.positions();
        if (x[tri[0]].z() > 0.07 && x[tri[1]].z() > 0.07 && x[tri[2]].z() > 0.07) continue; // the open top
        liverTris.push_back(tri);
        liverUv.push_back(liverUvWhole[t]);
    }
    parts.push_back({"liver", sim::TriMesh::fromArrays(liverWhole.positions(), std::move(liverTris), "liver"),
                     CsgOp::Union, std::move(liverUv)});
    // Gallbladder: a pear in its bed under the liver (its top 13 mm inside the liver), fundus at
    // +y, tapering to the neck at −y; two UV islands (left and right halves).
    const sim::Vec3 gc(0, -0.005, 0.012), gr(0.016, 0.042, 0.016);
    const sim::TriMesh gallUndeformed = sim::makeEllipsoidSurface(gc, gr, slices / 2, slices / 4);
    std::vector<CornerUv> gallUv =
        latLongUv(gallUndeformed, gc, gr, {{0.62, 0.52, 0.79, 0.98}, {0.81, 0.52, 0.98, 0.98}});
    std::vector<sim::Vec3> gp = gallUndeformed.positions();
    for (sim::Vec3& x : gp) {
        const double t = std::clamp((gc.y() - x.y()) / gr.y(), 0.0, 1.0); // 0 at the middle, 1 at the neck
        const double k = 1.0 - 0.55 * t * t;
        x.x() = gc.x() + k * (x.x() - gc.x());
        x.z() = gc.z() + k * (x.z() - gc.z());
    }
    parts.push_back({"gallbladder", sim::TriMesh::fromArrays(std::move(gp), gallUndeformed.triangles(), "gallbladder"),
                     CsgOp::Union, std::move(gallUv)});
    // Cystic duct: an open tube from the neck down to the common bile duct, 3.5 cm long, 2 cm of
    // it free between them: room for two clips on each side of the cut.
    const sim::Vec3 da(0, -0.043, 0.009), db(0.012, -0.075, 0.001);
    sim::TriMesh duct = uncapped(sim::makeTubeSurface(da, db, 0.0025, slices / 4, slices / 4), da, db, "cystic_duct");
    std::vector<CornerUv> ductUv = tubeUv(duct, da, db, 0.0025, {0.62, 0.27, 0.79, 0.48}, {}, {});
    parts.push_back({"cystic_duct", std::move(duct), CsgOp::Union, std::move(ductUv)});
    // Common bile duct: an open tube past the duct's end, overlapping it.
    const sim::Vec3 ca(0.011, -0.068, 0.003), cb(0.02, -0.125, -0.008);
    sim::TriMesh cbd =
        uncapped(sim::makeTubeSurface(ca, cb, 0.004, slices / 4, slices / 4), ca, cb, "common_bile_duct");
    std::vector<CornerUv> cbdUv = tubeUv(cbd, ca, cb, 0.004, {0.62, 0.02, 0.79, 0.23}, {}, {});
    parts.push_back({"common_bile_duct", std::move(cbd), CsgOp::Union, std::move(cbdUv)});
    // Cystic artery: a closed, capped tube up to the gallbladder's neck, its end inside it.
    const sim::Vec3 aa(0.024, -0.07, 0.008), ab(0.008, -0.036, 0.012);
    sim::TriMesh artery = sim::makeTubeSurface(aa, ab, 0.0015, slices / 6, slices / 6);
    std::vector<CornerUv> arteryUv =
        tubeUv(artery, aa, ab, 0.0015, {0.81, 0.14, 0.98, 0.48}, {0.81, 0.02, 0.885, 0.12}, {0.905, 0.02, 0.98, 0.12});
    parts.push_back({"cystic_artery", std::move(artery), CsgOp::Union, std::move(arteryUv)});
    return parts;
}

namespace {

/// The mesorectum of rectumAnatomy: the cube of (u along x, v around the rectum, w outwards).
RemeshPart mesorectumPart(int slices) {
    auto shell = [](const sim::Vec3& q) {
        const double x = -0.062 + 0.124 * q.x(), theta = (-95.0 + 190.0 * q.y()) * kPi / 180.0;
        const double deg = std::abs(theta) * 180.0 / kPi;
        const double lobes = 0.0009 * smoothstep(20, 45, deg) * std::sin(2 * kPi * x / 0.028) * std::sin(6 * theta);
        const double ri = 0.0225, ro = 0.032 + lobes;
        const double ex = std::max(0.0, std::abs(x) - 0.048) / 0.014, et = std::max(0.0, deg - 70) / 25;
        const double thin = std::sqrt(std::max(0.45, 1 - ex * ex)) * std::sqrt(std::max(0.45, 1 - et * et));
        const double r = ri + q.z() * (ro - ri) * thin;
        return sim::Vec3(x, 0.01 + r * std::sin(theta), -0.032 + r * std::cos(theta));
    };
    GridSurface g;
    addMappedCube(g, {slices, slices / 2, 4}, shell, {0.02, 0.02, 0.58, 0.98}, {0.62, 0.52, 0.98, 0.98},
                  {0.62, 0.27, 0.98, 0.48});
    return g.part("mesorectum");
}

/// The pelvic side walls and sacral hollow of rectumAnatomy, facing the axis.
RemeshPart pelvicWallPart(int slices) {
    auto wall = [](double s, double t) {
        const double x = -0.1 + 0.21 * s, phi = (55.0 + 250.0 * t) * kPi / 180.0;
        const double sacrum = std::pow(std::max(0.0, -std::cos(phi)), 2) * (0.004 + 0.006 * s);
        const double r = 0.075 + sacrum;
        return sim::Vec3(x, 0.01 - r * std::sin(phi), -0.025 + r * std::cos(phi));
    };
    const Rect island{0.02, 0.02, 0.58, 0.98};
    GridSurface g;
    g.add(
        slices / 2, slices, wall, [island](double s, double t) { return island.at(s, t); }, false);
    return g.part("pelvic_wall");
}

/// The peritoneal reflection of rectumAnatomy: a shallow dome facing −x.
RemeshPart peritoneumPart(int slices) {
    constexpr double R = 0.075;
    auto dome = [](double s, double t) {
        const double a = 2 * kPi * t;
        return sim::Vec3(0.11 + 0.01 * (1 - s * s), 0.01 + s * R * std::cos(a), -0.025 + s * R * std::sin(a));
    };
    const Rect island{0.62, 0.02, 0.98, 0.23};
    auto uv = [island](double s, double t) {
        const double a = 2 * kPi * t;
        return island.at(0.5 + 0.5 * s * std::cos(a), 0.5 + 0.5 * s * std::sin(a));
    };
    GridSurface g;
    g.add(slices / 8, slices, dome, uv, true);
    return g.part("peritoneum");
}

} // namespace

std::vector<RemeshPart> rectumAnatomy(int slices) {
    std::vector<RemeshPart> parts;
    parts.push_back(mesorectumPart(slices));
    const sim::Vec3 ra(-0.1, 0.01, -0.032), rb(0.11, 0.01, -0.032);
    sim::TriMesh rectum = uncapped(sim::makeTubeSurface(ra, rb, 0.0246, slices, slices / 2), ra, rb, "rectum");
    std::vector<CornerUv> rectumUv = tubeUv(rectum, ra, rb, 0.0246, {0.62, 0.52, 0.98, 0.98}, {}, {});
    parts.push_back({"rectum", std::move(rectum), CsgOp::Union, std::move(rectumUv)});
    parts.push_back(pelvicWallPart(slices));
    parts.push_back(peritoneumPart(slices));
    return parts;
}

} // namespace viscera::bake
