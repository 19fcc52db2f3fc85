#include "common.glsl"
// G-buffer fill [A Fig. 7.4] with the multi-layer tissue material [A §6.2.2]:
//   RT0 RGBA16F  normal (octahedral x, y) | linear view depth (m) | material id
//   RT1 RGBA8    roughness | metallic | thickness / range | reflection
//   RT2 RGBA8    diffuse r, g, b | heat
//   RT3 RGBA8    velocity x, y (0.5 + 4·Δuv) | flag: painted samples / 255 | flag: material flags / 255
in vec3 vNormal;
in vec3 vRest;
in float vThickness;
in float vSamples;
in float vHeat;
in vec4 vOverlay;
in vec4 vClip;
in vec4 vPrevClip;
in float vViewDepth;

layout(location = 0) out vec4 oG0;
layout(location = 1) out vec4 oG1;
layout(location = 2) out vec4 oG2;
layout(location = 3) out vec4 oG3;

uniform float uMaterialId;
uniform vec3 uSurfaceColour;
uniform vec3 uGranularColour;
uniform vec3 uConnectiveColour;
uniform vec3 uSubmucosaColour;
uniform vec4 uLayerWeights;   // surface, granular, connective, submucosa
uniform vec4 uLayerFrequency; // cells per metre, same order
uniform vec3 uFibreAxis;
uniform float uRoughness;
uniform float uGranularRoughness;
uniform float uMetallic;
uniform float uReflection;
uniform float uFlags;
uniform float uThicknessRange;
uniform int uDoubleSided;
uniform int uScreenDoor; // 1: drawn in every other pixel (authoring translucency)

void main() {
    if (uScreenDoor != 0 && ((int(gl_FragCoord.x) + int(gl_FragCoord.y)) & 1) == 0) discard;
    vec3 n = normalize(vNormal);
    if (uDoubleSided != 0 && !gl_FrontFacing) n = -n;

    // Layer masks on the rest position, so the pattern is carried by the deforming tissue.
    float granule = smoothstep(0.45, 0.8, valueNoise(vRest * uLayerFrequency.y));
    vec3 q = vRest * uLayerFrequency.z;
    q += uFibreAxis * (dot(q, uFibreAxis) * -0.85); // stretch cells along the fibre axis
    float fibre = pow(1.0 - abs(2.0 * valueNoise(q) - 1.0), 6.0);
    float ridge = 1.0 - abs(2.0 * fbm2(vRest * uLayerFrequency.w) - 1.0);
    float thin = 1.0 - clamp(vThickness / (0.5 * uThicknessRange), 0.0, 1.0);
    float vessel = smoothstep(0.9, 0.975, ridge) * mix(0.45, 1.0, thin);

    vec3 diffuse = uSurfaceColour * uLayerWeights.x;
    diffuse = mix(diffuse, uGranularColour, uLayerWeights.y * granule);
    diffuse = mix(diffuse, uConnectiveColour, uLayerWeights.z * fibre);
    diffuse = mix(diffuse, uSubmucosaColour, uLayerWeights.w * vessel);
    diffuse = mix(diffuse, vOverlay.rgb, clamp(vOverlay.a, 0.0, 1.0)); // authoring overlay
    float roughness = clamp(uRoughness + uGranularRoughness * (granule - 0.5), 0.04, 1.0);

    vec2 ndc = vClip.xy / vClip.w, prevNdc = vPrevClip.xy / vPrevClip.w;
    vec2 velocity = clamp(0.5 + 4.0 * 0.5 * (ndc - prevNdc), 0.0, 1.0);

    oG0 = vec4(encodeNormal(n), vViewDepth, uMaterialId);
    oG1 = vec4(roughness, uMetallic, clamp(vThickness / uThicknessRange, 0.0, 1.0), uReflection);
    oG2 = vec4(clamp(diffuse, 0.0, 1.0), clamp(vHeat, 0.0, 1.0));
    oG3 = vec4(velocity, vSamples / 255.0, uFlags / 255.0);
}
