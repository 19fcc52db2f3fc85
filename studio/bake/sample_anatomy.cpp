#include "bake/sample_anatomy.hpp"

#include "sim/mesh/generators.hpp"

#include <cmath>

namespace viscera::bake {
namespace {

/// The tube without its end caps: triangles with every vertex on an end plane are dropped.
sim::TriMesh uncapped(const sim::TriMesh& tube, const sim::Vec3& a, const sim::Vec3& b) {
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
    return sim::TriMesh::fromArrays(tube.positions(), std::move(kept), "ureter");
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
    tris.erase(tris.begin() + long(hole));
    std::vector<RemeshPart> parts;
    parts.push_back({"cortex", sim::TriMesh::fromArrays(std::move(p), std::move(tris), "cortex"), CsgOp::Union});
    parts.push_back(
        {"pelvis",
         sim::makeEllipsoidSurface(sim::Vec3(0.012, 0, 0), sim::Vec3(0.018, 0.014, 0.01), slices / 2, slices / 4),
         CsgOp::Union});
    const sim::Vec3 ua(0.022, -0.006, 0), ub(0.03, -0.09, -0.004);
    parts.push_back(
        {"ureter", uncapped(sim::makeTubeSurface(ua, ub, 0.004, slices / 3, slices / 3), ua, ub), CsgOp::Union});
    parts.push_back({"artery",
                     sim::makeTubeSurface(sim::Vec3(0.015, 0.008, 0.004), sim::Vec3(0.06, 0.02, 0.01), 0.003,
                                          slices / 4, slices / 8),
                     CsgOp::Union});
    return parts;
}

} // namespace viscera::bake
