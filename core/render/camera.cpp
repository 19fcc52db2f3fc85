#include "render/camera.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

namespace viscera::render {

Eigen::Matrix4f lookAt(const Eigen::Vector3f& eye, const Eigen::Vector3f& target, const Eigen::Vector3f& up) {
    const Eigen::Vector3f f = (target - eye).normalized();
    Eigen::Vector3f s = f.cross(up);
    if (s.squaredNorm() < 1e-12f)
        s = f.cross(std::abs(f.z()) < 0.9f ? Eigen::Vector3f::UnitZ() : Eigen::Vector3f::UnitY());
    s.normalize();
    const Eigen::Vector3f u = s.cross(f);
    Eigen::Matrix4f m = Eigen::Matrix4f::Identity();
    m.block<1, 3>(0, 0) = s.transpose();
    m.block<1, 3>(1, 0) = u.transpose();
    m.block<1, 3>(2, 0) = -f.transpose();
    m(0, 3) = -s.dot(eye);
    m(1, 3) = -u.dot(eye);
    m(2, 3) = f.dot(eye);
    return m;
}

Eigen::Matrix4f frustum(float l, float r, float b, float t, float n, float f) {
    Eigen::Matrix4f m = Eigen::Matrix4f::Zero();
    m(0, 0) = 2 * n / (r - l);
    m(0, 2) = (r + l) / (r - l);
    m(1, 1) = 2 * n / (t - b);
    m(1, 2) = (t + b) / (t - b);
    m(2, 2) = -(f + n) / (f - n);
    m(2, 3) = -2 * f * n / (f - n);
    m(3, 2) = -1;
    return m;
}

Eigen::Matrix4f perspective(float fovYDeg, float aspect, float n, float f) {
    const float t = n * std::tan(0.5f * fovYDeg * float(M_PI) / 180.0f);
    return frustum(-t * aspect, t * aspect, -t, t, n, f);
}

namespace {
EyeView makeEye(const Camera& c, const Eigen::Vector3f& shift, const Eigen::Matrix4f& projection) {
    EyeView e;
    e.position = c.position + shift;
    e.view = lookAt(e.position, c.target + shift, c.up);
    e.projection = projection;
    e.viewProjection = projection * e.view;
    e.inverseViewProjection = e.viewProjection.inverse();
    e.right = e.view.block<1, 3>(0, 0).transpose();
    e.up = e.view.block<1, 3>(1, 0).transpose();
    e.forward = -e.view.block<1, 3>(2, 0).transpose();
    e.nearPlane = c.nearPlane;
    e.farPlane = c.farPlane;
    return e;
}
} // namespace

EyeView monoEye(const Camera& c, float aspect) {
    return makeEye(c, Eigen::Vector3f::Zero(), perspective(c.fovYDeg, aspect, c.nearPlane, c.farPlane));
}

std::array<EyeView, 2> stereoEyes(const Camera& c, const StereoSettings& st, float aspect) {
    const EyeView mono = monoEye(c, aspect);
    const float n = c.nearPlane;
    const float top = n * std::tan(0.5f * c.fovYDeg * float(M_PI) / 180.0f);
    const float halfW = top * aspect;
    const float half = 0.5f * st.eyeSeparation;
    const float shift = half * n / st.convergenceDistance;
    // Left eye sits at −half along right; its window shifts towards +x by `shift` (and vice versa).
    return {makeEye(c, -half * mono.right, frustum(-halfW + shift, halfW + shift, -top, top, n, c.farPlane)),
            makeEye(c, half * mono.right, frustum(-halfW - shift, halfW - shift, -top, top, n, c.farPlane))};
}

Camera frameBounds(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi, const Eigen::Vector3f& direction,
                   float fovYDeg, float fill) {
    Camera c;
    const Eigen::Vector3f centre = 0.5f * (lo + hi);
    const float radius = std::max(0.5f * (hi - lo).norm(), 1e-4f);
    const float halfFov = 0.5f * fovYDeg * float(M_PI) / 180.0f;
    const float dist = radius / (std::sin(halfFov) * std::max(fill, 0.05f));
    c.fovYDeg = fovYDeg;
    c.target = centre;
    c.position = centre - direction.normalized() * dist;
    c.up = std::abs(direction.normalized().z()) > 0.95f ? Eigen::Vector3f::UnitY() : Eigen::Vector3f::UnitZ();
    c.nearPlane = std::max(1e-3f, 0.05f * (dist - radius));
    c.farPlane = dist + 4.0f * radius;
    return c;
}

} // namespace viscera::render
