#include "sim/suture/anastomosis.hpp"

#include "sim/mesh/generators.hpp"
#include "sim/util/error.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <sstream>

namespace viscera::sim::suture {
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

Vec3 closestOnTri(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
    // Projection clamped to the triangle (adequate for the gauge).
    const Vec3 n = (b - a).cross(c - a).normalized();
    const Vec3 q = p - n.dot(p - a) * n;
    const Vec3 v0 = b - a, v1 = c - a, v2 = q - a;
    const double d00 = v0.dot(v0), d01 = v0.dot(v1), d11 = v1.dot(v1), d20 = v2.dot(v0), d21 = v2.dot(v1);
    const double den = d00 * d11 - d01 * d01;
    double v = (d11 * d20 - d01 * d21) / den, w = (d00 * d21 - d01 * d20) / den;
    v = std::clamp(v, 0.0, 1.0);
    w = std::clamp(w, 0.0, 1.0 - v);
    return a + v * v0 + w * v1;
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

double anastomosisHandle(const AnastomosisSpec& s) { return 0.5 * std::numbers::pi * s.needleRadius; }

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
                out.push_back({needlePose(prev + dPhi * f / s.transferFrames, s.needleCentre + s.transferDistance, g0), 0});
            for (int f = 1; f <= s.transferFrames; ++f) // in
                out.push_back({needlePose(phi, s.needleCentre + s.transferDistance * (1.0 - double(f) / s.transferFrames), g0), 0});
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
    for (int f = 1; f <= s.pullFrames; ++f) out.push_back({park, total * f / s.pullFrames});
    return out;
}

std::string formatTrajectory(const std::vector<NeedleFrame>& frames) {
    std::string out = "# viscera needle trajectory v1: px py pz qw qx qy qz pull (metres, unit quaternion)\n";
    char buf[256];
    for (const NeedleFrame& f : frames) {
        const Eigen::Quaterniond q(f.pose.linear());
        const Vec3 p = f.pose.translation();
        std::snprintf(buf, sizeof buf, "%.9g %.9g %.9g %.12g %.12g %.12g %.12g %.9g\n", p.x(), p.y(), p.z(), q.w(), q.x(),
                      q.y(), q.z(), f.pull);
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
        while (n < 8 && ls >> v[n]) ++n;
        std::string rest;
        if (n != 8 || (ls >> rest))
            throw InputError(origin + ": line " + std::to_string(lineNo) + ": expected 8 numbers (px py pz qw qx qy qz pull)");
        for (double d : v)
            if (!std::isfinite(d)) throw InputError(origin + ": line " + std::to_string(lineNo) + ": values must be finite");
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
            for (auto& v : t) v += off;
            tets.push_back(t);
        }
    }
    return TetMesh::fromArrays(std::move(pos), std::move(tets), "sim::suture::mergeMeshes()");
}

ClosureGauge::ClosureGauge(const TetMesh& m, int32_t firstB) {
    const auto& x = m.positions();
    const auto& vmap = m.boundaryVertexMap();
    std::vector<int32_t> bA, bB;
    for (int32_t v : vmap) (v < firstB ? bA : bB).push_back(v);
    auto nearest = [&](int32_t v, const std::vector<int32_t>& other) {
        double d = std::numeric_limits<double>::infinity();
        for (int32_t o : other) d = std::min(d, (x[v] - x[o]).norm());
        return d;
    };
    std::vector<double> dA(bA.size()), dB(bB.size());
    double minD = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < bA.size(); ++i) minD = std::min(minD, dA[i] = nearest(bA[i], bB));
    for (size_t i = 0; i < bB.size(); ++i) dB[i] = nearest(bB[i], bA);
    std::vector<uint8_t> facing(x.size(), 0);
    for (size_t i = 0; i < bA.size(); ++i)
        if (dA[i] <= 1.5 * minD) m_facingA.push_back(bA[i]), facing[bA[i]] = 1;
    for (size_t i = 0; i < bB.size(); ++i)
        if (dB[i] <= 1.5 * minD) m_facingB.push_back(bB[i]), facing[bB[i]] = 1;
    const TriMesh& b = m.boundary();
    for (const Tri& t : b.triangles()) {
        const std::array<int32_t, 3> v = {vmap[t[0]], vmap[t[1]], vmap[t[2]]};
        if (!(facing[v[0]] && facing[v[1]] && facing[v[2]])) continue;
        (v[0] < firstB ? m_trisA : m_trisB).push_back(v);
    }
}

ClosureMetrics ClosureGauge::measure(const std::vector<Vec3>& x) const {
    ClosureMetrics r;
    auto side = [&](const std::vector<int32_t>& verts, const std::vector<std::array<int32_t, 3>>& tris) {
        for (int32_t v : verts) {
            double best = std::numeric_limits<double>::infinity(), signedDist = 0;
            for (const auto& t : tris) {
                const Vec3 q = closestOnTri(x[v], x[t[0]], x[t[1]], x[t[2]]);
                const double d = (x[v] - q).norm();
                if (d < best) {
                    best = d;
                    const Vec3 n = (x[t[1]] - x[t[0]]).cross(x[t[2]] - x[t[0]]).normalized(); // outward
                    signedDist = n.dot(x[v] - q);
                }
            }
            if (!std::isfinite(best)) continue;
            r.maxGap = std::max(r.maxGap, signedDist);
            r.maxPenetration = std::max(r.maxPenetration, -signedDist);
        }
    };
    side(m_facingB, m_trisA);
    side(m_facingA, m_trisB);
    r.finite = std::isfinite(r.maxGap) && std::isfinite(r.maxPenetration);
    return r;
}

} // namespace viscera::sim::suture
