#pragma once
/// Painted against uniform light sampling on one scene [A §6.3.2]: the error each makes against
/// the many-sample reference near the light, and what each frame costs, measured in one run (the
/// renderer bench's rule: interleaved frames, the minimum of each). Used by `bench_render --case`
/// and by the studio's side-by-side comparison.
#include "render/headless.hpp"

#include <functional>
#include <optional>

namespace viscera::render {

struct SamplingComparison {
    Image reference, uniform, painted; ///< final frames
    /// RMSE against the reference (8-bit units) over the pixels near the light and over every
    /// drawn pixel.
    double rmseNearUniform = 0, rmseNearPainted = 0, rmseUniform = 0, rmsePainted = 0;
    double msUniform = 0, msPainted = 0; ///< frame time, the minimum over the timed frames
    size_t nearPixels = 0, drawnPixels = 0;
    float nearDistance = 0; ///< m: a pixel is near the light when its surface lies this close or closer
};

/// Renders `view` with `base` as the reference (SampleMode::Reference), uniform 1× (Uniform,
/// uniformSamples 1) and painted (Painted, unpainted vertices at 1×), then times `frames` frames
/// of the last two interleaved. "Near the light" is the quarter of the drawn pixels whose surface
/// is nearest to the light. `progress(done, total)` is called after each frame; returning false
/// stops the comparison (nullopt).
std::optional<SamplingComparison> compareSampling(HeadlessRenderer& renderer, const SceneView& view,
                                                  const RenderSettings& base, int frames,
                                                  const std::function<bool(int, int)>& progress = {});

} // namespace viscera::render
