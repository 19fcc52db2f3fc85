#include "sim/clip/clip_flattening.hpp"

#include "sim/collision/distance.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace viscera::sim {

namespace {
[[noreturn]] void fail(const std::string& rule) {
    throw std::invalid_argument("sim::ClipFlattening::create(): " + rule);
}
} // namespace

Vec3 closestPointOnPolyline(const Vec3& p, const Vec3* P, size_t count, const std::vector<int32_t>& segments) {
    if (count == 1) return P[0];
    double best = std::numeric_limits<double>::infinity();
    Vec3 q = P[0];
    auto visit = [&](size_t i) {
        const double t = closestParameterOnSegment(p, P[i], P[i + 1]);
        const Vec3 c = P[i] + t * (P[i + 1] - P[i]);
        const double d = (c - p).squaredNorm();
        if (d < best) {
            best = d;
            q = c;
        }
    };
    if (segments.empty())
        for (size_t i = 0; i + 1 < count; ++i)
            visit(i);
    else
        for (int32_t i : segments)
            visit(static_cast<size_t>(i));
    return q;
}

std::unique_ptr<ClipFlattening> ClipFlattening::create(const ClipAttachment& clip, const std::vector<Vec3>& x,
                                                       const std::vector<Vec3>& skeleton, const FlattenSettings& s) {
    if (!(std::isfinite(s.eta) && s.eta >= 0)) fail("settings.eta must be finite and >= 0");
    if (!(std::isfinite(s.gamma) && s.gamma > 0)) fail("settings.gamma must be finite and > 0");
    if (!(std::isfinite(s.minDistance) && s.minDistance > 0)) fail("settings.minDistance must be finite and > 0");
    if (!(std::isfinite(s.influence) && s.influence > s.minDistance))
        fail("settings.influence must be finite and > minDistance");
    if (!(s.maxSqueeze >= 0 && s.maxSqueeze < 1)) fail("settings.maxSqueeze must be in [0, 1)");
    if (skeleton.size() < 2) fail("the skeleton polyline needs at least 2 points");
    for (size_t i = 0; i < skeleton.size(); ++i)
        if (!skeleton[i].allFinite()) fail("skeleton[" + std::to_string(i) + "] is not finite");
    for (size_t i = 0; i < x.size(); ++i)
        if (!x[i].allFinite()) fail("renderPositions[" + std::to_string(i) + "] is not finite");

    std::unique_ptr<ClipFlattening> f(new ClipFlattening());
    f->m_settings = s;
    f->m_renderCount = x.size();
    f->m_skeletonCount = skeleton.size();
    f->m_skeleton0 = skeleton;
    const Vec3 cmP = closestPointOnPolyline(clip.centre(), skeleton.data(), skeleton.size());
    double reach = 0; // largest distance of a candidate from the centre's projection
    for (size_t i = 0; i < x.size(); ++i) {
        const Vec3 p = closestPointOnPolyline(x[i], skeleton.data(), skeleton.size());
        if ((p - cmP).norm() < s.influence) {
            f->m_candidates.push_back(static_cast<int32_t>(i));
            reach = std::max(reach, (x[i] - cmP).norm());
        }
    }
    // Keep the segments that come within 2 × reach of the centre's projection (room for the
    // vessel to deform; a vertex's nearest segment is never farther than the vertex itself).
    for (size_t i = 0; i + 1 < skeleton.size(); ++i) {
        const double t = closestParameterOnSegment(cmP, skeleton[i], skeleton[i + 1]);
        const Vec3 c = skeleton[i] + t * (skeleton[i + 1] - skeleton[i]);
        if ((c - cmP).norm() <= 2 * reach + s.influence) f->m_segments.push_back(static_cast<int32_t>(i));
    }
    return f;
}

bool ClipFlattening::flattenInto(const ClipAttachment& clip, const std::vector<Vec3>& x, std::vector<Vec3>& out) const {
    return run(clip, x, nullptr, true, out);
}

bool ClipFlattening::flattenInto(const ClipAttachment& clip, const std::vector<Vec3>& x,
                                 const std::vector<Vec3>& skeletonNow, std::vector<Vec3>& out) const {
    if (skeletonNow.size() != m_skeletonCount) {
        out = x;
        return false;
    }
    return run(clip, x, skeletonNow.data(), false, out);
}

bool ClipFlattening::run(const ClipAttachment& clip, const std::vector<Vec3>& x, const Vec3* skel, bool carried,
                         std::vector<Vec3>& out) const {
    out.resize(x.size());
    std::copy(x.begin(), x.end(), out.begin());
    if (x.size() != m_renderCount) return false;
    // Current polyline: the given one, or the application one carried with the clip (only the
    // kept segments' end points are needed; transform them into a small local buffer).
    thread_local std::vector<Vec3> carriedBuf;
    if (carried) {
        carriedBuf.resize(m_skeleton0.size());
        const Mat3 Q = clip.relativeRotation();
        const Vec3 c0 = clip.applicationCentre(), c = clip.centre();
        for (int32_t i : m_segments) {
            carriedBuf[i] = Q * (m_skeleton0[i] - c0) + c;
            carriedBuf[i + 1] = Q * (m_skeleton0[i + 1] - c0) + c;
        }
        skel = carriedBuf.data();
    }
    const FlattenSettings& s = m_settings;
    const Vec3 n = clip.jawNormal();
    const Vec3 cmP = closestPointOnPolyline(clip.centre(), skel, m_skeletonCount, m_segments);
    const double fEdge = s.eta / std::pow(s.influence, s.gamma);
    for (int32_t i : m_candidates) {
        const Vec3& xi = x[i];
        if (!xi.allFinite()) continue;
        const Vec3 p = closestPointOnPolyline(xi, skel, m_skeletonCount, m_segments);
        const double si = (p - cmP).norm();
        if (!(si < s.influence)) continue;
        const double f = s.eta / std::pow(std::max(si, s.minDistance), s.gamma) - fEdge;
        const Vec3 r = xi - p;
        const double rho = r.norm();
        if (!(rho > 1e-12) || !(f > 0)) continue;
        const double m = std::min(f, s.maxSqueeze * rho);
        out[i] = xi - (m * (r.dot(n) / rho)) * n;
    }
    return true;
}

} // namespace viscera::sim
