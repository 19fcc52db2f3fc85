#include "render/area_light.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

namespace viscera::render {

LightFrame lightFrame(const AreaLight& light, const EyeView& cam) {
    LightFrame f;
    Eigen::Vector3f n, up;
    if (light.followCamera) {
        f.center = cam.position + light.cameraOffset.x() * cam.right + light.cameraOffset.y() * cam.up +
                   light.cameraOffset.z() * cam.forward;
        n = cam.forward;
        up = cam.up;
    } else {
        f.center = light.center;
        n = light.direction.normalized();
        up = light.up;
    }
    Eigen::Vector3f u = up.cross(n);
    if (u.squaredNorm() < 1e-10f) u = n.unitOrthogonal();
    u.normalize();
    const Eigen::Vector3f v = n.cross(u).normalized();
    f.normal = n;
    f.halfU = 0.5f * light.width * u;
    f.halfV = 0.5f * light.height * v;
    f.area = light.width * light.height;
    f.radiance = light.colour * (light.intensity / f.area);
    return f;
}

int samplesForDistance(const std::vector<DistanceBand>& bands, float d) {
    for (const DistanceBand& b : bands)
        if (d <= b.maxDistance) return b.samples;
    return bands.empty() ? 1 : bands.back().samples;
}

int samplesFor(const SamplingSettings& s, float d, int painted) {
    switch (s.mode) {
    case SampleMode::Uniform:
        return s.uniformSamples;
    case SampleMode::Distance:
        return samplesForDistance(s.bands, d);
    case SampleMode::Painted:
        return painted > 0 ? painted : s.uniformSamples;
    case SampleMode::Reference:
        return s.referenceSamples;
    }
    return 1;
}

Eigen::Vector2f samplePoint(int i, int m) {
    uint32_t bits = static_cast<uint32_t>(i);
    bits = (bits << 16u) | (bits >> 16u);
    bits = ((bits & 0x55555555u) << 1u) | ((bits & 0xAAAAAAAAu) >> 1u);
    bits = ((bits & 0x33333333u) << 2u) | ((bits & 0xCCCCCCCCu) >> 2u);
    bits = ((bits & 0x0F0F0F0Fu) << 4u) | ((bits & 0xF0F0F0F0u) >> 4u);
    bits = ((bits & 0x00FF00FFu) << 8u) | ((bits & 0xFF00FF00u) >> 8u);
    const float radical = float(bits) * 2.3283064365386963e-10f;
    float y = radical + 0.5f / float(m);
    y -= std::floor(y);
    return {(float(i) + 0.5f) / float(m), y};
}

float reflectionConeHalfAngle(float roughness, float cutoff) {
    const float a = std::max(roughness * roughness, 1e-3f);
    const float a2 = a * a;
    const float num = 1.0f - a2 / std::sqrt(cutoff);
    if (num <= 0.0f) return float(M_PI);
    const float cos2 = num / (1.0f - a2);
    const float thetaH = std::acos(std::sqrt(std::clamp(cos2, 0.0f, 1.0f)));
    return std::min(2.0f * thetaH, float(M_PI));
}

} // namespace viscera::render
