// Sharpen [A §6.3.3]: unsharp mask with the 4-neighbour Laplacian.
in vec2 vUv;
out vec4 oColour;
uniform sampler2D uInput;
uniform vec2 uTexel;
uniform float uAmount;
void main() {
    vec3 c = texture(uInput, vUv).rgb;
    vec3 n = texture(uInput, vUv + vec2(0.0, uTexel.y)).rgb + texture(uInput, vUv - vec2(0.0, uTexel.y)).rgb +
             texture(uInput, vUv + vec2(uTexel.x, 0.0)).rgb + texture(uInput, vUv - vec2(uTexel.x, 0.0)).rgb;
    oColour = vec4(max(c + uAmount * (4.0 * c - n), 0.0), 1.0);
}
