#pragma once
/// Closest-point queries between points, segments and triangles (metres, world frame). Used by
/// the tool shapes and the polygon narrow phase [A §5.2.6]. All O(1), allocation-free.
#include "sim/mesh/tri_mesh.hpp"

namespace viscera::sim {

/// Closest point of triangle (a, b, c) to p, with its barycentric coordinates (sum 1, each in
/// [0, 1]). Degenerate triangles are handled (the closest point of the nearest edge).
struct TrianglePoint {
    Vec3 point = Vec3::Zero();
    Vec3 bary = Vec3(1, 0, 0);
};
TrianglePoint closestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

/// Parameter t in [0, 1] of the point of segment (a, b) closest to p (0 for a zero-length one).
double closestParameterOnSegment(const Vec3& p, const Vec3& a, const Vec3& b);

/// Closest points between segments (p0, p1) and (q0, q1): parameters s, t in [0, 1].
struct SegmentPair {
    double s = 0, t = 0;
    Vec3 onP = Vec3::Zero(), onQ = Vec3::Zero();
};
SegmentPair closestPointsSegments(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1);

/// Closest points between segment (s0, s1) and triangle (a, b, c). When the segment pierces the
/// triangle both points coincide (distance 0).
struct SegmentTrianglePair {
    Vec3 onSegment = Vec3::Zero();
    TrianglePoint onTriangle;
    double distance = 0;
};
SegmentTrianglePair closestPointsSegmentTriangle(const Vec3& s0, const Vec3& s1, const Vec3& a, const Vec3& b,
                                                 const Vec3& c);

} // namespace viscera::sim
