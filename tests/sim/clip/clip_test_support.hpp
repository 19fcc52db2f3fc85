#pragma once
// Shared fixtures for the sim/clip tests: a vessel tube, a clip across it, rigid and twist motions.
#include "sim/clip/clip_attachment.hpp"
#include "sim/mesh/generators.hpp"

#include <Eigen/Geometry>

#include <cmath>
#include <memory>
#include <vector>

namespace viscera::sim::testing {

/// Hollow tube along +z from the origin: radius 2–3 mm, `length` m, `rings` cells along it.
inline std::unique_ptr<TetMesh> clipTube(double length = 0.06, int rings = 16, int slices = 16) {
    HollowTubeSpec s;
    s.start = Vec3::Zero();
    s.end = Vec3(0, 0, length);
    s.innerRadius = 0.002;
    s.outerRadius = 0.003;
    s.slices = slices;
    s.layers = 1;
    s.rings = rings;
    return makeHollowTubeTetMesh(s);
}

/// A clip across a tube whose axis passes through `centre` along `axis`: two jaw plates of
/// half width `halfWidth` (across the vessel, along `across`), half thickness `halfDepth` (along
/// the axis) whose inner faces lie at ±gap from the centre along `normal` (jaw closing
/// direction). Vertices: the 8 corners of each jaw plate (plates 0.5 mm thick). Contact points:
/// a grid on each inner face. Bounds: the box spanned by the jaws.
inline ClipDesc clipAcross(const Vec3& centre, const Vec3& axis, const Vec3& normal, double gap,
                           double halfWidth = 0.004, double halfDepth = 0.001, int grid = 9) {
    ClipDesc d;
    const Vec3 a = axis.normalized(), n = (normal - normal.dot(a) * a).normalized(), w = a.cross(n);
    Mat3 axes;
    axes << w, n, a;
    const double plate = 0.0005;
    d.bounds = ClipBounds::box(centre, axes, Vec3(halfWidth, gap + plate, halfDepth));
    d.jawNormal = n;
    for (int side : {-1, 1})
        for (double h : {gap, gap + plate})
            for (int i : {-1, 1})
                for (int j : {-1, 1})
                    d.vertices.push_back(centre + side * h * n + i * halfWidth * w + j * halfDepth * a);
    for (int side : {-1, 1})
        for (int i = 0; i < grid; ++i)
            for (int j = 0; j < grid; ++j) {
                const double u = -1 + 2.0 * i / (grid - 1), v = -1 + 2.0 * j / (grid - 1);
                d.contactPoints.push_back(centre + side * gap * n + u * halfWidth * w + v * halfDepth * a);
            }
    return d;
}

inline std::vector<Vec3> transformed(const std::vector<Vec3>& x, const Mat3& M, const Vec3& t,
                                     const Vec3& about = Vec3::Zero()) {
    std::vector<Vec3> y(x.size());
    for (size_t i = 0; i < x.size(); ++i)
        y[i] = M * (x[i] - about) + about + t;
    return y;
}

inline Mat3 rotationAbout(const Vec3& axis, double angle) {
    return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
}

inline double maxDeviation(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
    double m = 0;
    for (size_t i = 0; i < a.size(); ++i)
        m = std::max(m, (a[i] - b[i]).norm());
    return m;
}

} // namespace viscera::sim::testing
