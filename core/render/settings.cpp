#include "render/settings.hpp"

#include <cmath>
#include <stdexcept>

namespace viscera::render {

bool PostSettings::anyEnabled() const {
    return depthOfField.enabled || chromaticAberration.enabled || toneMapping.enabled || colourCurve.enabled ||
           sharpen.enabled || noise.enabled || radialMask.enabled;
}

void PostSettings::disableAll() {
    depthOfField.enabled = chromaticAberration.enabled = toneMapping.enabled = false;
    colourCurve.enabled = sharpen.enabled = noise.enabled = radialMask.enabled = false;
}

namespace {
[[noreturn]] void fail(const std::string& field, const std::string& rule) {
    throw std::invalid_argument("render::RenderSettings: " + field + ": " + rule);
}
bool finite3(const Eigen::Vector3f& v) {
    return v.allFinite();
}
} // namespace

void RenderSettings::validate() const {
    if (width < 8 || height < 8 || width > 8192 || height > 8192)
        fail("width/height", "must be in [8, 8192], got " + std::to_string(width) + "x" + std::to_string(height));
    if (stereo.mode == StereoMode::SideBySide && width % 2 != 0) fail("width", "must be even for side-by-side stereo");
    if (!finite3(camera.position) || !finite3(camera.target) || !finite3(camera.up))
        fail("camera", "position, target and up must be finite");
    if ((camera.target - camera.position).norm() <= 0.0f) fail("camera", "target equals position");
    if (!(camera.fovYDeg > 1.0f && camera.fovYDeg < 170.0f)) fail("camera.fovYDeg", "must be in (1, 170)");
    if (!(camera.nearPlane > 0.0f && camera.farPlane > camera.nearPlane))
        fail("camera.nearPlane/farPlane", "need 0 < near < far");
    if (!(light.width > 0.0f && light.height > 0.0f)) fail("light.width/height", "must be positive");
    if (!(light.intensity >= 0.0f)) fail("light.intensity", "must be non-negative");
    if (!light.followCamera && light.direction.norm() <= 0.0f) fail("light.direction", "must be non-zero");
    const SamplingSettings& s = sampling;
    if (s.uniformSamples < 1 || s.uniformSamples > 255) fail("sampling.uniformSamples", "must be in [1, 255]");
    if (s.referenceSamples < 1 || s.referenceSamples > 4096) fail("sampling.referenceSamples", "must be in [1, 4096]");
    if (s.bands.empty() || s.bands.size() > 8) fail("sampling.bands", "needs 1 to 8 bands");
    for (size_t i = 0; i < s.bands.size(); ++i) {
        const std::string f = "sampling.bands[" + std::to_string(i) + "]";
        if (s.bands[i].samples < 1 || s.bands[i].samples > 255) fail(f + ".samples", "must be in [1, 255]");
        if (!(s.bands[i].maxDistance > 0.0f)) fail(f + ".maxDistance", "must be positive");
        if (i > 0 && !(s.bands[i].maxDistance > s.bands[i - 1].maxDistance))
            fail(f + ".maxDistance", "bands must be sorted by increasing distance");
    }
    if (!(s.coneCutoff > 0.0f && s.coneCutoff < 1.0f)) fail("sampling.coneCutoff", "must be in (0, 1)");
    const ColourCurve& c = post.colourCurve;
    if (c.points.size() < 2 || c.points.size() > 8) fail("post.colourCurve.points", "needs 2 to 8 points");
    for (size_t i = 1; i < c.points.size(); ++i)
        if (!(c.points[i].x() > c.points[i - 1].x()))
            fail("post.colourCurve.points[" + std::to_string(i) + "]", "x must increase");
    if (!(post.radialMask.outer > post.radialMask.inner)) fail("post.radialMask", "outer must exceed inner");
    if (!(post.depthOfField.maxRadiusPx >= 0.0f && post.depthOfField.maxRadiusPx <= 16.0f))
        fail("post.depthOfField.maxRadiusPx", "must be in [0, 16]");
    if (stereo.mode != StereoMode::Off &&
        !(stereo.eyeSeparation > 0.0f && stereo.convergenceDistance > camera.nearPlane))
        fail("stereo", "needs eyeSeparation > 0 and convergenceDistance > camera.nearPlane");
}

} // namespace viscera::render
