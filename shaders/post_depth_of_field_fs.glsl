#include "common.glsl"
// Depth of field [A §6.3.3]: circle of confusion from the G-buffer's linear depth, gathered over a
// 24-tap Vogel disk; taps sharper than their distance are ignored (no in-focus bleeding).
in vec2 vUv;
out vec4 oColour;
uniform sampler2D uInput;
uniform sampler2D uG0;
uniform vec2 uTexel;
uniform float uFocusDistance;
uniform float uFocusRange;
uniform float uBlurPerMetre;
uniform float uMaxRadius;

float coc(vec2 uv) {
    float z = texture(uG0, uv).z;
    if (z <= 0.0) z = uFocusDistance + uFocusRange + uMaxRadius / max(uBlurPerMetre, 1e-3); // background
    return clamp((abs(z - uFocusDistance) - uFocusRange) * uBlurPerMetre, 0.0, uMaxRadius);
}

void main() {
    float c0 = coc(vUv);
    vec3 sum = texture(uInput, vUv).rgb;
    float wsum = 1.0;
    if (c0 > 0.5) {
        for (int i = 0; i < 24; ++i) {
            float r = c0 * sqrt((float(i) + 0.5) / 24.0);
            float phi = float(i) * 2.39996323;
            vec2 uv = vUv + r * vec2(cos(phi), sin(phi)) * uTexel;
            float w = coc(uv) >= 0.5 * r ? 1.0 : 0.0;
            sum += w * texture(uInput, uv).rgb;
            wsum += w;
        }
    }
    oColour = vec4(sum / wsum, 1.0);
}
