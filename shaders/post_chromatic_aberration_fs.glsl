// Chromatic aberration [A §6.3.3]: red and blue sampled radially outwards and inwards.
in vec2 vUv;
out vec4 oColour;
uniform sampler2D uInput;
uniform float uStrength; // offset at the corner, fraction of the image
void main() {
    vec2 dir = (vUv - 0.5) * (uStrength / 0.70710678);
    float r = texture(uInput, vUv + dir).r;
    float g = texture(uInput, vUv).g;
    float b = texture(uInput, vUv - dir).b;
    oColour = vec4(r, g, b, 1.0);
}
