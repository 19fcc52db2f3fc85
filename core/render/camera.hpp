#pragma once
/// View and projection matrices (OpenGL conventions: right-handed eye space looking down −z,
/// clip z in [−1, 1]) and the off-axis stereo frustums of [B ch. 4].
#include "render/settings.hpp"

#include <Eigen/Core>

#include <array>

namespace viscera::render {

/// One eye's matrices. `position` in metres, world frame.
struct EyeView {
    Eigen::Matrix4f view = Eigen::Matrix4f::Identity();
    Eigen::Matrix4f projection = Eigen::Matrix4f::Identity();
    Eigen::Matrix4f viewProjection = Eigen::Matrix4f::Identity();
    Eigen::Matrix4f inverseViewProjection = Eigen::Matrix4f::Identity();
    Eigen::Vector3f position = Eigen::Vector3f::Zero();
    Eigen::Vector3f forward{0.0f, 0.0f, -1.0f};
    Eigen::Vector3f right{1.0f, 0.0f, 0.0f};
    Eigen::Vector3f up{0.0f, 1.0f, 0.0f};
    float nearPlane = 0.01f, farPlane = 1.0f;
};

Eigen::Matrix4f lookAt(const Eigen::Vector3f& eye, const Eigen::Vector3f& target, const Eigen::Vector3f& up);
/// glFrustum: near-plane window [left, right] × [bottom, top] at distance `nearPlane`.
Eigen::Matrix4f frustum(float left, float right, float bottom, float top, float nearPlane, float farPlane);
Eigen::Matrix4f perspective(float fovYDeg, float aspect, float nearPlane, float farPlane);

/// Mono eye for `camera` at the aspect ratio width/height.
EyeView monoEye(const Camera& camera, float aspect);

/// Left (0) and right (1) eyes: parallel view directions, eye positions ±separation/2 along the
/// camera's right axis, frustums shifted by (separation/2)·near/convergence so that a point at the
/// convergence distance has the same image position in both eyes (zero parallax).
std::array<EyeView, 2> stereoEyes(const Camera& camera, const StereoSettings& stereo, float aspect);

/// A camera looking at the box [lo, hi] from `direction` (towards the box), far enough that the
/// bounding sphere fills `fill` of the vertical field of view.
Camera frameBounds(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi, const Eigen::Vector3f& direction,
                   float fovYDeg = 55.0f, float fill = 0.8f);

} // namespace viscera::render
