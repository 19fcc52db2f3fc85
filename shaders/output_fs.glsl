#include "common.glsl"
// Output encoding: linear HDR → display values (clamp to [0, 1], sRGB curve), 8 bits per channel.
in vec2 vUv;
out vec4 oColour;
uniform sampler2D uInput;
void main() { oColour = vec4(linearToSrgb(texture(uInput, vUv).rgb), 1.0); }
