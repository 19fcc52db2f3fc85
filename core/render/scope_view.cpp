#include "render/scope_view.hpp"

#include <limits>

namespace viscera::render {

void viewThroughScope(RenderSettings& s, const ToolPoses::Scope& scope) {
    if (!scope.present || !scope.tip.allFinite() || !scope.view.allFinite() || !scope.up.allFinite()) return;
    if (!(scope.view.norm() > 0.5) || !(scope.up.norm() > 0.5)) return;
    const Eigen::Vector3f tip = scope.tip.cast<float>();
    s.camera.position = tip;
    s.camera.target = tip + kScopeWorkingDistance * scope.view.normalized().cast<float>();
    s.camera.up = scope.up.normalized().cast<float>();
    s.camera.fovYDeg = static_cast<float>(scope.fovDeg);
    s.camera.nearPlane = 0.005f;
    s.camera.farPlane = 0.6f;
    // The light ring around the optic: at the tip, facing the view.
    s.light.followCamera = true;
    s.light.cameraOffset = Eigen::Vector3f(0.004f, 0.0f, 0.0f); // the fibres beside the lens
    s.light.width = 0.008f;
    s.light.height = 0.004f;
    const float d = kScopeWorkingDistance;
    s.light.intensity = 0.9f * d * d;
    s.sampling.bands = {{0.8f * d, 8}, {1.0f * d, 4}, {std::numeric_limits<float>::infinity(), 1}};
    // A scope focuses at its working distance (depth of field, where the case turns it on).
    s.post.depthOfField.focusDistance = d;
    s.post.depthOfField.focusRange = 0.5f * d;
}

} // namespace viscera::render
