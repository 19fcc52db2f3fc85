#include "common.glsl"
// Sensor noise [A §6.3.3]: monochrome grain from an integer hash of the pixel and the seed, added
// in display space.
in vec2 vUv;
out vec4 oColour;
uniform sampler2D uInput;
uniform float uAmount;
uniform int uSeed;
void main() {
    uvec2 p = uvec2(gl_FragCoord.xy);
    uint h = hashU(p.x * 1973u + hashU(p.y * 9277u + uint(uSeed) * 26699u));
    float n = float(h & 0xffffu) / 65535.0 * 2.0 - 1.0;
    vec3 c = linearToSrgb(texture(uInput, vUv).rgb) + uAmount * n;
    oColour = vec4(srgbToLinear(c), 1.0);
}
