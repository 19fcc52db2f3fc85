// Red–cyan anaglyph [B ch. 4] from the encoded left and right eye images ("optimised" mix: the
// red channel takes the left eye's green and blue, which lowers retinal rivalry).
in vec2 vUv;
out vec4 oColour;
uniform sampler2D uLeft;
uniform sampler2D uRight;
void main() {
    vec3 l = texture(uLeft, vUv).rgb, r = texture(uRight, vUv).rgb;
    oColour = vec4(0.7 * l.g + 0.3 * l.b, r.g, r.b, 1.0);
}
