#include "render/sampling_compare.hpp"

#include <algorithm>

namespace viscera::render {

std::optional<SamplingComparison> compareSampling(HeadlessRenderer& r, const SceneView& view,
                                                  const RenderSettings& base, int frames,
                                                  const std::function<bool(int, int)>& progress) {
    frames = std::max(1, frames);
    const int total = 3 + 2 * frames;
    int done = 0;
    auto step = [&] { return !progress || progress(++done, total); };
    RenderSettings ref = base, uni = base, painted = base;
    ref.sampling.mode = SampleMode::Reference;
    uni.sampling.mode = SampleMode::Uniform;
    uni.sampling.uniformSamples = 1;
    painted.sampling.mode = SampleMode::Painted;
    painted.sampling.uniformSamples = 1;
    SamplingComparison out;
    r.setSettings(ref);
    r.renderFrame(view);
    out.reference = r.readPixels();
    // near the light: the nearest quarter of the drawn pixels
    const std::vector<float> dist = r.renderer().distanceMap(r.renderer().light().center);
    std::vector<float> drawn;
    for (float d : dist)
        if (d >= 0) drawn.push_back(d);
    if (!step()) return std::nullopt;
    std::vector<uint8_t> nearMask(dist.size(), 0), drawnMask(dist.size(), 0);
    if (!drawn.empty()) {
        const size_t q = (drawn.size() - 1) / 4;
        std::nth_element(drawn.begin(), drawn.begin() + q, drawn.end());
        out.nearDistance = drawn[q];
        for (size_t i = 0; i < dist.size(); ++i) {
            drawnMask[i] = dist[i] >= 0;
            nearMask[i] = dist[i] >= 0 && dist[i] <= out.nearDistance;
            out.nearPixels += nearMask[i];
            out.drawnPixels += drawnMask[i];
        }
    }
    r.setSettings(uni);
    r.renderFrame(view);
    out.uniform = r.readPixels();
    if (!step()) return std::nullopt;
    r.setSettings(painted);
    r.renderFrame(view);
    out.painted = r.readPixels();
    if (!step()) return std::nullopt;
    out.rmseNearUniform = compareImages(out.reference, out.uniform, nearMask).rmse;
    out.rmseNearPainted = compareImages(out.reference, out.painted, nearMask).rmse;
    out.rmseUniform = compareImages(out.reference, out.uniform, drawnMask).rmse;
    out.rmsePainted = compareImages(out.reference, out.painted, drawnMask).rmse;
    // frame times: interleaved, the minimum of each (the machine is shared and noisy)
    uni.timePasses = painted.timePasses = false;
    out.msUniform = out.msPainted = 1e300;
    for (int f = 0; f < frames; ++f) {
        r.setSettings(uni);
        out.msUniform = std::min(out.msUniform, r.renderFrame(view).totalMs);
        if (!step()) return std::nullopt;
        r.setSettings(painted);
        out.msPainted = std::min(out.msPainted, r.renderFrame(view).totalMs);
        if (!step()) return std::nullopt;
    }
    return out;
}

} // namespace viscera::render
