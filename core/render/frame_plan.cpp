#include "render/frame_plan.hpp"

namespace viscera::render {

FrameLayout frameLayout(const RenderSettings& s) {
    FrameLayout l;
    l.outputWidth = s.width;
    l.outputHeight = s.height;
    l.eyes = s.stereo.mode == StereoMode::Off ? 1 : 2;
    l.eyeWidth = s.stereo.mode == StereoMode::SideBySide ? s.width / 2 : s.width;
    l.eyeHeight = s.height;
    return l;
}

std::vector<PassDesc> planFrame(const RenderSettings& s) {
    const FrameLayout l = frameLayout(s);
    const PostSettings& p = s.post;
    const std::pair<bool, PassKind> effects[] = {{p.depthOfField.enabled, PassKind::DepthOfField},
                                                 {p.chromaticAberration.enabled, PassKind::ChromaticAberration},
                                                 {p.toneMapping.enabled, PassKind::ToneMapping},
                                                 {p.colourCurve.enabled, PassKind::ColourCurve},
                                                 {p.sharpen.enabled, PassKind::Sharpen},
                                                 {p.noise.enabled, PassKind::Noise},
                                                 {p.radialMask.enabled, PassKind::RadialMask}};
    const Viewport eyeVp{0, 0, l.eyeWidth, l.eyeHeight};
    std::vector<PassDesc> plan;
    for (int eye = 0; eye < l.eyes; ++eye) {
        plan.push_back({PassKind::GBuffer, eye, Target::None, Target::GBuffer, eyeVp});
        plan.push_back({PassKind::Lighting, eye, Target::GBuffer, Target::Lit, eyeVp});
        Target current = Target::Lit;
        for (const auto& [on, kind] : effects) {
            if (!on) continue;
            const Target next = current == Target::PostA ? Target::PostB : Target::PostA;
            plan.push_back({kind, eye, current, next, eyeVp});
            current = next;
        }
        PassDesc out{PassKind::Output, eye, current, Target::Final, eyeVp};
        if (s.stereo.mode == StereoMode::SideBySide) out.viewport.x = eye * l.eyeWidth;
        if (s.stereo.mode == StereoMode::Anaglyph) out.output = eye == 0 ? Target::EyeLeft : Target::EyeRight;
        plan.push_back(out);
    }
    if (s.stereo.mode == StereoMode::Anaglyph)
        plan.push_back({PassKind::StereoCompose, 0, Target::EyeLeft, Target::Final,
                        Viewport{0, 0, l.outputWidth, l.outputHeight}});
    return plan;
}

const char* passName(PassKind k) {
    switch (k) {
    case PassKind::GBuffer:
        return "gbuffer";
    case PassKind::Lighting:
        return "lighting";
    case PassKind::DepthOfField:
        return "depth_of_field";
    case PassKind::ChromaticAberration:
        return "chromatic_aberration";
    case PassKind::ToneMapping:
        return "tone_mapping";
    case PassKind::ColourCurve:
        return "colour_curve";
    case PassKind::Sharpen:
        return "sharpen";
    case PassKind::Noise:
        return "noise";
    case PassKind::RadialMask:
        return "radial_mask";
    case PassKind::Output:
        return "output";
    case PassKind::StereoCompose:
        return "stereo_compose";
    }
    return "?";
}

bool isPostEffect(PassKind k) {
    return k >= PassKind::DepthOfField && k <= PassKind::RadialMask;
}

} // namespace viscera::render
