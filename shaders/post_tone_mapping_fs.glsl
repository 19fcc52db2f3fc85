// Tone mapping [A §6.3.3]: exposure, then the ACES filmic fit or Reinhard; output linear in [0, 1].
in vec2 vUv;
out vec4 oColour;
uniform sampler2D uInput;
uniform float uExposure;
uniform int uOperator; // 0 ACES, 1 Reinhard
void main() {
    vec3 x = max(texture(uInput, vUv).rgb * uExposure, 0.0);
    vec3 y = uOperator == 0 ? clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0)
                            : x / (1.0 + x);
    oColour = vec4(y, 1.0);
}
