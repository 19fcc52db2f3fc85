// Radial gradient mask [A §6.3.3]: the round field of view of the scope.
in vec2 vUv;
out vec4 oColour;
uniform sampler2D uInput;
uniform float uAspect;
uniform float uInner;
uniform float uOuter;
uniform vec3 uColour;
void main() {
    vec2 d = (vUv - 0.5) * vec2(uAspect, 1.0);
    float r = length(d) / length(vec2(0.5 * uAspect, 0.5));
    float keep = 1.0 - smoothstep(uInner, uOuter, r);
    oColour = vec4(mix(uColour, texture(uInput, vUv).rgb, keep), 1.0);
}
