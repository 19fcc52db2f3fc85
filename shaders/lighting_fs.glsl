#include "common.glsl"
// Deferred lighting: Cook–Torrance PBR lit by a rectangular area light sampled by Monte Carlo
// [A §6.3.2], with subsurface scattering from the baked thickness [A eq. 6.8–6.10]:
//   diffuse  k_d (1 − k_sss) c/π  L Σ cosθ_i (n·ω_i) α / r²                     (eq. 6.17)
//   sss      k_d k_sss c C e^{−σT}/π L Σ cosθ_i wrap(n·ω_i) α / r²              (eq. 6.15)
//   specular L Σ_{cone} k_s DFG / (4 (n·ω_o)(n·ω_i)) (n·ω_i) cosθ_i α / r²       (eq. 6.21)
// with α = A/m and m = m(d) (eq. 6.16), a painted class, a uniform count or the reference count.
in vec2 vUv;
out vec4 oColour;

uniform sampler2D uG0;
uniform sampler2D uG1;
uniform sampler2D uG2;
uniform sampler2D uG3;
uniform sampler2D uDepth;
uniform mat4 uInvViewProj;
uniform vec3 uEyePos;

uniform vec3 uLightCenter;
uniform vec3 uLightNormal;
uniform vec3 uLightHalfU;
uniform vec3 uLightHalfV;
uniform vec3 uLightRadiance;
uniform float uLightArea;

uniform int uMode; // 0 uniform, 1 distance, 2 painted, 3 reference
uniform int uUniformSamples;
uniform int uReferenceSamples;
uniform int uBandCount;
uniform float uBandMax[8];
uniform int uBandSamples[8];
uniform int uUseCone;
uniform float uConeCutoff;
uniform int uSubsurface;

uniform vec3 uAmbient;
uniform vec3 uBackground;
uniform vec3 uEnvironment;
uniform float uThicknessRange;
uniform float uKsss[32];
uniform vec3 uSssColour[32];
uniform vec3 uSigma[32];
uniform float uF0[32];

vec2 samplePoint(int i, int m) {
    float radical = float(bitfieldReverse(uint(i))) * 2.3283064365386963e-10;
    return vec2((float(i) + 0.5) / float(m), fract(radical + 0.5 / float(m)));
}

int sampleCount(float d, float painted) {
    if (uMode == 0) return uUniformSamples;
    if (uMode == 3) return uReferenceSamples;
    if (uMode == 2) return painted > 0.5 ? int(painted + 0.5) : uUniformSamples;
    for (int b = 0; b < uBandCount; ++b)
        if (d <= uBandMax[b]) return uBandSamples[b];
    return uBandSamples[uBandCount - 1];
}

float coneCos(float roughness) {
    float a = max(roughness * roughness, 1e-3);
    float a2 = a * a;
    float num = 1.0 - a2 / sqrt(uConeCutoff);
    if (num <= 0.0) return -1.0;
    float thetaH = acos(sqrt(clamp(num / (1.0 - a2), 0.0, 1.0)));
    return cos(min(2.0 * thetaH, PI));
}

void main() {
    float depth = texture(uDepth, vUv).r;
    if (depth >= 1.0) {
        oColour = vec4(uBackground, 1.0);
        return;
    }
    vec4 g0 = texture(uG0, vUv), g1 = texture(uG1, vUv), g2 = texture(uG2, vUv), g3 = texture(uG3, vUv);
    vec4 world = uInvViewProj * vec4(2.0 * vUv - 1.0, 2.0 * depth - 1.0, 1.0);
    vec3 P = world.xyz / world.w;
    vec3 N = decodeNormal(g0.xy);
    vec3 V = normalize(uEyePos - P);
    if (dot(N, V) < 0.0) N = normalize(N + V * (0.01 - dot(N, V))); // silhouettes: keep n·v > 0
    int id = clamp(int(g0.w + 0.5), 0, 31);
    float roughness = g1.r, metallic = g1.g, T = g1.b * uThicknessRange, reflection = g1.a;
    vec3 albedo = g2.rgb;
    float heat = g2.a;
    float ksss = uSubsurface != 0 ? uKsss[id] : 0.0;

    // Heat tint of dissected tissue: coagulated (pale) then charred.
    float coag = smoothstep(0.15, 0.55, heat), charred = smoothstep(0.65, 1.0, heat);
    albedo = mix(albedo, vec3(0.78, 0.70, 0.62), coag);
    albedo = mix(albedo, vec3(0.10, 0.07, 0.05), charred);
    ksss *= 1.0 - coag;
    roughness = mix(roughness, 0.8, smoothstep(0.15, 0.8, heat));

    vec3 F0 = mix(vec3(uF0[id]), albedo, metallic);
    float nv = max(dot(N, V), 1e-4);
    vec3 Fv = F0 + (1.0 - F0) * pow(max(1.0 - nv, 0.0), 5.0);
    vec3 kd = (1.0 - Fv) * (1.0 - metallic);
    vec3 R = reflect(-V, N);
    float cosCone = uUseCone != 0 ? coneCos(roughness) : -2.0;
    float a = max(roughness * roughness, 1e-3), a2 = a * a;
    float k = (roughness + 1.0) * (roughness + 1.0) / 8.0;
    float gv = nv / (nv * (1.0 - k) + k);

    float d = length(P - uLightCenter);
    int m = sampleCount(d, g3.z * 255.0);
    float alpha = uLightArea / float(m);
    float diffSum = 0.0, sssSum = 0.0;
    vec3 specSum = vec3(0.0);
    for (int i = 0; i < m; ++i) {
        vec2 s = samplePoint(i, m);
        vec3 Lp = uLightCenter + (2.0 * s.x - 1.0) * uLightHalfU + (2.0 * s.y - 1.0) * uLightHalfV;
        vec3 toL = Lp - P;
        float r2 = max(dot(toL, toL), 1e-8);
        vec3 wi = toL * inversesqrt(r2);
        float cosL = max(dot(uLightNormal, -wi), 0.0);
        float g = cosL * alpha / r2;
        float ndl = dot(N, wi);
        float nl = max(ndl, 0.0);
        diffSum += g * nl;
        sssSum += g * max((ndl + 0.5) / 1.5, 0.0);
        if (nl > 0.0 && dot(wi, R) >= cosCone) {
            vec3 H = normalize(wi + V);
            float nh = max(dot(N, H), 0.0);
            float dd = nh * nh * (a2 - 1.0) + 1.0;
            float D = a2 / (PI * dd * dd);
            float G = gv * nl / (nl * (1.0 - k) + k);
            // pow of a negative base is undefined in GLSL: with the light at the eye, H = V and
            // dot(H, V) rounds above 1 (NaN specks in the highlight before this clamp).
            vec3 F = F0 + (1.0 - F0) * pow(clamp(1.0 - dot(H, V), 0.0, 1.0), 5.0);
            specSum += (D * G * F / (4.0 * nv * nl)) * nl * g;
        }
    }
    vec3 L = uLightRadiance;
    vec3 diffuse = kd * (1.0 - ksss) * albedo / PI * L * diffSum;
    vec3 sss = kd * ksss * albedo * uSssColour[id] * exp(-uSigma[id] * T) / PI * L * sssSum;
    vec3 specular = L * specSum;
    vec3 mucus = reflection * Fv * uEnvironment;
    oColour = vec4(diffuse + sss + specular + mucus + uAmbient * albedo, 1.0);
}
