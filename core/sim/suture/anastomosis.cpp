#include "sim/suture/anastomosis.hpp"

#include "sim/mesh/generators.hpp"
#include "sim/util/error.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <sstream>

namespace viscera::sim {
namespace {

std::vector<int32_t> ringAt(const TetMesh& m, const Vec3& point, const Vec3& axis) {
    std::vector<int32_t> out;
    for (int32_t v = 0; v < static_cast<int32_t>(m.vertexCount()); ++v)
        if (std::abs((m.positions()[v] - point).dot(axis)) < 1e-9) out.push_back(v);
    return out;
}

/// Needle pose in the radial plane at angle φ: centre at ρ_c on the radius, turned by γ.
Eigen::Isometry3d needlePose(double phi, double rhoC, double gamma) {
    const Vec3 er(std::cos(phi), std::sin(phi), 0), ez = Vec3::UnitZ();
    const Vec3 E1 = er, E2 = -ez, E3 = E1.cross(E2);
    Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
    p.linear().col(0) = std::cos(gamma) * E1 + std::sin(gamma) * E2;
    p.linear().col(1) = -std::sin(gamma) * E1 + std::cos(gamma) * E2;
    p.linear().col(2) = E3;
    p.translation() = rhoC * er;
    return p;
}

} // namespace

AnastomosisModel makeAnastomosisTubes(const AnastomosisSpec& s) {
    AnastomosisModel m;
    m.wide = makeHollowTubeTetMesh(s.wide);
    m.narrow = makeHollowTubeTetMesh(s.narrow);
    m.wideFixed = ringAt(*m.wide, s.wide.start, (s.wide.end - s.wide.start).normalized());
    m.narrowFixed = ringAt(*m.narrow, s.narrow.end, (s.narrow.end - s.narrow.start).normalized());
    return m;
}

double anastomosisHandle(const AnastomosisSpec& s) {
    return 0.5 * std::numbers::pi * s.needleRadius;
}

std::vector<NeedleFrame> makeAnastomosisTrajectory(const AnastomosisSpec& s) {
    std::vector<NeedleFrame> out;
    const double g0 = -0.5 * std::numbers::pi; // tip at the outermost-lower point, needle outside
    const int turnFrames = static_cast<int>(std::lround(360.0 / s.degreesPerFrame));
    const double dPhi = 2 * std::numbers::pi / s.stitches;
    for (int k = 0; k < s.stitches; ++k) {
        const double phi = k * dPhi;
        if (k > 0) {
            const double prev = phi - dPhi;
            for (int f = 1; f <= s.transferFrames; ++f) // out
                out.push_back({needlePose(prev, s.needleCentre + s.transferDistance * f / s.transferFrames, g0), 0});
            for (int f = 1; f <= s.transferFrames; ++f) // around
                out.push_back(
                    {needlePose(prev + dPhi * f / s.transferFrames, s.needleCentre + s.transferDistance, g0), 0});
            for (int f = 1; f <= s.transferFrames; ++f) // in
                out.push_back(
                    {needlePose(phi, s.needleCentre + s.transferDistance * (1.0 - double(f) / s.transferFrames), g0),
                     0});
        }
        for (int f = 1; f <= turnFrames; ++f)
            out.push_back({needlePose(phi, s.needleCentre, g0 + 2 * std::numbers::pi * f / turnFrames), 0});
    }
    // Park the needle outside and pull.
    const double phiEnd = (s.stitches - 1) * dPhi;
    const int segments = 2 * s.stitches - 1;
    const double total = s.slack + s.pullPerSegment * segments;
    for (int f = 1; f <= s.transferFrames; ++f)
        out.push_back({needlePose(phiEnd, s.needleCentre + s.transferDistance * f / s.transferFrames, g0), 0});
    const Eigen::Isometry3d park = needlePose(phiEnd, s.needleCentre + s.transferDistance, g0);
    for (int f = 1; f <= s.pullFrames; ++f)
        out.push_back({park, total * f / s.pullFrames});
    return out;
}

std::string formatTrajectory(const std::vector<NeedleFrame>& frames) {
    std::string out = "# viscera needle trajectory v1: px py pz qw qx qy qz pull (metres, unit quaternion)\n";
    char buf[256];
    for (const NeedleFrame& f : frames) {
        const Eigen::Quaterniond q(f.pose.linear());
        const Vec3 p = f.pose.translation();
        std::snprintf(buf, sizeof buf, "%.9g %.9g %.9g %.12g %.12g %.12g %.12g %.9g\n", p.x(), p.y(), p.z(), q.w(),
                      q.x(), q.y(), q.z(), f.pull);
        out += buf;
    }
    return out;
}

std::vector<NeedleFrame> parseTrajectory(std::string_view text, const std::string& origin) {
    std::vector<NeedleFrame> out;
    std::istringstream in{std::string(text)};
    std::string line;
    int lineNo = 0;
    while (std::getline(in, line)) {
        ++lineNo;
        const auto hash = line.find('#');
        if (hash != std::string::npos) line.resize(hash);
        if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
        std::istringstream ls(line);
        double v[8];
        int n = 0;
        while (n < 8 && ls >> v[n])
            ++n;
        std::string rest;
        if (n != 8 || (ls >> rest))
            throw InputError(origin + ": line " + std::to_string(lineNo) +
                             ": expected 8 numbers (px py pz qw qx qy qz pull)");
        for (double d : v)
            if (!std::isfinite(d))
                throw InputError(origin + ": line " + std::to_string(lineNo) + ": values must be finite");
        Eigen::Quaterniond q(v[3], v[4], v[5], v[6]);
        if (std::abs(q.norm() - 1) > 1e-6)
            throw InputError(origin + ": line " + std::to_string(lineNo) + ": quaternion must have unit norm");
        if (v[7] < 0) throw InputError(origin + ": line " + std::to_string(lineNo) + ": pull must not be negative");
        NeedleFrame f;
        f.pose.linear() = q.normalized().toRotationMatrix();
        f.pose.translation() = Vec3(v[0], v[1], v[2]);
        f.pull = v[7];
        out.push_back(f);
    }
    if (out.empty()) throw InputError(origin + ": the trajectory has no frames");
    return out;
}

std::unique_ptr<TetMesh> mergeMeshes(const std::vector<const TetMesh*>& meshes, std::vector<int32_t>* offsets) {
    std::vector<Vec3> pos;
    std::vector<Tet> tets;
    if (offsets) offsets->clear();
    for (const TetMesh* m : meshes) {
        const auto off = static_cast<int32_t>(pos.size());
        if (offsets) offsets->push_back(off);
        pos.insert(pos.end(), m->positions().begin(), m->positions().end());
        for (Tet t : m->tets()) {
            for (auto& v : t)
                v += off;
            tets.push_back(t);
        }
    }
    return TetMesh::fromArrays(std::move(pos), std::move(tets), "sim::mergeMeshes()");
}

namespace {

bool insideTet(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, double tol) {
    Eigen::Matrix3d M;
    M << b - a, c - a, d - a;
    const double det = M.determinant();
    if (!(std::abs(det) > 0)) return false;
    const Vec3 l = M.inverse() * (p - a);
    return l.minCoeff() > tol && l.sum() < 1 - tol;
}

Vec3 closestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
    // Ericson, region tests: exact closest point.
    const Vec3 ab = b - a, ac = c - a, ap = p - a;
    const double d1 = ab.dot(ap), d2 = ac.dot(ap);
    if (d1 <= 0 && d2 <= 0) return a;
    const Vec3 bp = p - b;
    const double d3 = ab.dot(bp), d4 = ac.dot(bp);
    if (d3 >= 0 && d4 <= d3) return b;
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + d1 / (d1 - d3) * ab;
    const Vec3 cp = p - c;
    const double d5 = ab.dot(cp), d6 = ac.dot(cp);
    if (d6 >= 0 && d5 <= d6) return c;
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + d2 / (d2 - d6) * ac;
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
    const double den = 1 / (va + vb + vc);
    return a + ab * (vb * den) + ac * (vc * den);
}

} // namespace

ClosureGauge::ClosureGauge(const TetMesh& m, int32_t firstB) {
    const auto& x = m.positions();
    const auto& vmap = m.boundaryVertexMap();
    std::vector<int32_t> bA, bB;
    for (int32_t v : vmap)
        (v < firstB ? bA : bB).push_back(v);
    auto nearest = [&](int32_t v, const std::vector<int32_t>& other) {
        double d = std::numeric_limits<double>::infinity();
        for (int32_t o : other)
            d = std::min(d, (x[v] - x[o]).norm());
        return d;
    };
    std::vector<double> dist(x.size(), std::numeric_limits<double>::infinity());
    double minD = std::numeric_limits<double>::infinity();
    for (int32_t v : bA)
        minD = std::min(minD, dist[v] = nearest(v, bB));
    for (int32_t v : bB)
        dist[v] = nearest(v, bA);
    std::vector<uint8_t> facing(x.size(), 0), near(x.size(), 0);
    for (int32_t v : bA) {
        if (dist[v] <= 1.5 * minD) m_facingA.push_back(v), facing[v] = 1;
        if (dist[v] <= 3 * minD) near[v] = 1;
    }
    for (int32_t v : bB) {
        if (dist[v] <= 1.5 * minD) m_facingB.push_back(v), facing[v] = 1;
        if (dist[v] <= 3 * minD) near[v] = 1;
    }
    const TriMesh& b = m.boundary();
    for (const Tri& t : b.triangles()) {
        const std::array<int32_t, 3> v = {vmap[t[0]], vmap[t[1]], vmap[t[2]]};
        const bool isA = v[0] < firstB;
        if (facing[v[0]] && facing[v[1]] && facing[v[2]]) (isA ? m_trisA : m_trisB).push_back(v);
        if (near[v[0]] || near[v[1]] || near[v[2]]) (isA ? m_surfA : m_surfB).push_back(v);
    }
    for (const Tet& t : m.tets()) {
        bool close = false;
        for (int32_t v : t)
            close |= nearest(v, v < firstB ? bB : bA) <= 3 * minD;
        if (close) (t[0] < firstB ? m_tetsA : m_tetsB).push_back(t);
    }
    // Vertices that face the other body's surface: their rest projection onto the nearest facing
    // triangle of the other body is not on the triangle's border (an overhanging rim never closes).
    auto opposing = [&](const std::vector<int32_t>& verts, const std::vector<std::array<int32_t, 3>>& tris,
                        std::vector<int32_t>& out) {
        for (int32_t v : verts) {
            double best = std::numeric_limits<double>::infinity();
            bool interior = false;
            for (const auto& t : tris) {
                const Vec3 q = closestPointOnTriangle(x[v], x[t[0]], x[t[1]], x[t[2]]);
                const double d = (x[v] - q).norm();
                if (d < best) {
                    best = d;
                    const Vec3 n = (x[t[1]] - x[t[0]]).cross(x[t[2]] - x[t[0]]).normalized();
                    interior = std::abs(n.dot(x[v] - q)) > 0.999 * d;
                }
            }
            if (interior) out.push_back(v);
        }
    };
    opposing(m_facingA, m_trisB, m_opposingA);
    opposing(m_facingB, m_trisA, m_opposingB);
}

ClosureMetrics ClosureGauge::measure(const std::vector<Vec3>& x) const {
    ClosureMetrics r;
    auto distanceTo = [&](const Vec3& p, const std::vector<std::array<int32_t, 3>>& tris) {
        double best = std::numeric_limits<double>::infinity();
        for (const auto& t : tris)
            best = std::min(best, (p - closestPointOnTriangle(p, x[t[0]], x[t[1]], x[t[2]])).norm());
        return best;
    };
    auto inside = [&](const Vec3& p, const std::vector<Tet>& tets) {
        for (const Tet& t : tets) {
            const Vec3 lo = x[t[0]].cwiseMin(x[t[1]]).cwiseMin(x[t[2]]).cwiseMin(x[t[3]]);
            const Vec3 hi = x[t[0]].cwiseMax(x[t[1]]).cwiseMax(x[t[2]]).cwiseMax(x[t[3]]);
            if ((p.array() < lo.array()).any() || (p.array() > hi.array()).any()) continue;
            if (insideTet(p, x[t[0]], x[t[1]], x[t[2]], x[t[3]], 1e-12)) return true;
        }
        return false;
    };
    auto side = [&](const std::vector<int32_t>& facing, const std::vector<int32_t>& opposing,
                    const std::vector<std::array<int32_t, 3>>& otherFacing,
                    const std::vector<std::array<int32_t, 3>>& otherSurface, const std::vector<Tet>& otherTets) {
        for (int32_t v : facing) {
            if (!x[v].allFinite()) {
                r.finite = false;
                continue;
            }
            if (inside(x[v], otherTets)) r.maxPenetration = std::max(r.maxPenetration, distanceTo(x[v], otherSurface));
        }
        for (int32_t v : opposing)
            if (!inside(x[v], otherTets)) r.maxGap = std::max(r.maxGap, distanceTo(x[v], otherFacing));
    };
    side(m_facingB, m_opposingB, m_trisA, m_surfA, m_tetsA);
    side(m_facingA, m_opposingA, m_trisB, m_surfB, m_tetsB);
    r.finite = r.finite && std::isfinite(r.maxGap) && std::isfinite(r.maxPenetration);
    return r;
}

AnastomosisRun makeAnastomosisRun(const AnastomosisSpec& spec, SutureSettings settings) {
    AnastomosisModel model = makeAnastomosisTubes(spec);
    std::vector<int32_t> off;
    auto merged = mergeMeshes({model.wide.get(), model.narrow.get()}, &off);
    std::vector<int32_t> fixed = model.wideFixed;
    for (int32_t v : model.narrowFixed)
        fixed.push_back(v + off[1]);
    settings.needle.radius = spec.needleRadius;
    settings.needle.handle = anastomosisHandle(spec);
    AnastomosisRun run;
    run.frames = makeAnastomosisTrajectory(spec);
    run.narrowOffset = off[1];
    run.sim = SutureSimulation::create(std::move(merged), fixed, settings, run.frames.front().pose);
    return run;
}

} // namespace viscera::sim
