#include "common.glsl"
// Colour curve [A §6.3.3]: piecewise-linear curve on display values, then per-channel gain.
in vec2 vUv;
out vec4 oColour;
uniform sampler2D uInput;
uniform vec2 uPoints[8];
uniform int uCount;
uniform vec3 uGain;

float curve(float x) {
    if (x <= uPoints[0].x) return uPoints[0].y;
    for (int i = 1; i < uCount; ++i)
        if (x <= uPoints[i].x) {
            float t = (x - uPoints[i - 1].x) / (uPoints[i].x - uPoints[i - 1].x);
            return mix(uPoints[i - 1].y, uPoints[i].y, t);
        }
    return uPoints[uCount - 1].y;
}

void main() {
    vec3 c = linearToSrgb(texture(uInput, vUv).rgb);
    c = vec3(curve(c.r), curve(c.g), curve(c.b)) * uGain;
    oColour = vec4(srgbToLinear(c), 1.0);
}
