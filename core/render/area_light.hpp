#pragma once
/// Rectangular area light sampling [A §6.3.2] on the CPU: the sample count m(d) of eq. 6.16, the
/// sample pattern on the rectangle and the reflection cone of eq. 6.21. The lighting shader
/// (shaders/lighting_fs.glsl) implements the same rules; tests check these functions.
#include "render/camera.hpp"
#include "render/settings.hpp"

#include <Eigen/Core>

#include <vector>

namespace viscera::render {

/// The light in world space for one frame: centre, unit emitting normal, half-extent vectors.
struct LightFrame {
    Eigen::Vector3f center = Eigen::Vector3f::Zero();
    Eigen::Vector3f normal{0.0f, 0.0f, -1.0f};
    Eigen::Vector3f halfU{0.01f, 0.0f, 0.0f}; ///< m, half width along the rectangle's u axis
    Eigen::Vector3f halfV{0.0f, 0.005f, 0.0f};
    Eigen::Vector3f radiance = Eigen::Vector3f::Ones(); ///< colour · intensity / area
    float area = 2e-4f;                                 ///< m²
};
/// Places the light (following the mono camera when light.followCamera).
LightFrame lightFrame(const AreaLight& light, const EyeView& monoCamera);

/// m(d) [A eq. 6.16]: the samples of the first band with d ≤ maxDistance; the last band's count
/// beyond every band.
int samplesForDistance(const std::vector<DistanceBand>& bands, float distance);

/// Sample count a point takes under `settings` at distance d from the light centre, with the
/// painted class `painted` (0 = unpainted).
int samplesFor(const SamplingSettings& settings, float distance, int painted);

/// Sample i of m in the unit square: x = (i + ½)/m, y = frac(radicalInverse₂(i) + ½/m); one sample
/// is the centre (a point light), four form a Latin square.
Eigen::Vector2f samplePoint(int i, int m);

/// Half-angle (radians) of the cone around the reflection vector that holds the light directions
/// where the GGX lobe of `roughness` (α = roughness²) exceeds `cutoff` of its peak: 2·θh with
/// cos²θh = (1 − α²/√cutoff) / (1 − α²); π when the lobe is wider than the hemisphere.
float reflectionConeHalfAngle(float roughness, float cutoff);

} // namespace viscera::render
