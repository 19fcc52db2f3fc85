#pragma once
/// The passes of one frame, chosen from the settings before any backend runs them: G-buffer
/// [A Fig. 7.4], deferred lighting, one pass per enabled post effect [A §6.3.3] (a disabled effect
/// has no pass), output encoding, and for anaglyph stereo a compose pass [B ch. 4]. Each eye runs
/// its own chain. Targets: the lit image stays in Lit; post effects ping-pong between PostA and
/// PostB (Lit is never overwritten, so the unprocessed image stays readable).
#include "render/settings.hpp"

#include <string>
#include <vector>

namespace viscera::render {

enum class PassKind : uint8_t {
    GBuffer,
    Lighting,
    DepthOfField,
    ChromaticAberration,
    ToneMapping,
    ColourCurve,
    Sharpen,
    Noise,
    RadialMask,
    Output,       ///< HDR → 8-bit display values (clamp, sRGB) into the eye's viewport
    StereoCompose ///< anaglyph: left and right eye images → Final
};

enum class Target : uint8_t { None, GBuffer, Lit, PostA, PostB, EyeLeft, EyeRight, Final };

/// Pixel rectangle in a target, origin bottom-left.
struct Viewport {
    int x = 0, y = 0, width = 0, height = 0;
    friend bool operator==(const Viewport&, const Viewport&) = default;
};

struct PassDesc {
    PassKind kind = PassKind::GBuffer;
    int eye = 0; ///< 0 mono/left, 1 right
    Target input = Target::None;
    Target output = Target::None;
    Viewport viewport; ///< where `output` is written
};

/// Sizes the backend allocates: one eye's G-buffer/HDR size and the output size.
struct FrameLayout {
    int eyeWidth = 0, eyeHeight = 0;
    int outputWidth = 0, outputHeight = 0;
    int eyes = 1;
    friend bool operator==(const FrameLayout&, const FrameLayout&) = default;
};

FrameLayout frameLayout(const RenderSettings& settings);
/// The passes of a frame in execution order.
std::vector<PassDesc> planFrame(const RenderSettings& settings);
/// Stable lower-case name ("gbuffer", "lighting", "tone_mapping", …).
const char* passName(PassKind kind);
/// True for the post-effect passes (DepthOfField … RadialMask).
bool isPostEffect(PassKind kind);

} // namespace viscera::render
