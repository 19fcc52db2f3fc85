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
in vec2 vUv;
in vec3 vWorld;
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
// Material maps [A §6.2.2, Fig. 6.8-6.9]: bit 0 diffuse, 1 roughness, 2 metallic, 3 normal.
uniform int uMapMask;
uniform int uHasUv;            // 1: the mesh's UVs, 0: triplanar on the rest position
uniform float uTilesPerMetre;  // triplanar repeats per metre
uniform float uNormalStrength;
uniform sampler2D uDiffuseMap;   // sRGB texture: sampled linear
uniform sampler2D uRoughnessMap; // red channel
uniform sampler2D uMetallicMap;  // red channel
uniform sampler2D uNormalMap;    // tangent space, (n + 1) / 2
uniform int uHasThicknessMap;    // 1: the mesh's baked thickness per texel [A §6.3.1] (needs UVs)
uniform sampler2D uThicknessMap; // red = thickness / uThicknessRange

// Triplanar weights from the rest surface's normal (screen derivatives of the rest position, so
// the projection stays with the tissue as it deforms).
vec3 triplanarWeights() {
    vec3 nr = cross(dFdx(vRest), dFdy(vRest));
    float len = length(nr);
    vec3 w = len > 0.0 ? pow(abs(nr / len), vec3(4.0)) : vec3(1.0);
    return w / (w.x + w.y + w.z);
}

vec4 sampleMap(sampler2D map, vec3 w) {
    if (uHasUv != 0) return texture(map, vUv);
    vec3 p = vRest * uTilesPerMetre;
    return w.x * texture(map, p.yz) + w.y * texture(map, p.xz) + w.z * texture(map, p.xy);
}

// A tangent-space normal on the current surface through the cotangent frame of the texture
// coordinates `uv` on the deformed position (no stored tangents; follows the deformation).
vec3 perturbed(vec3 n, vec2 uv, vec3 tn) {
    vec3 dp1 = dFdx(vWorld), dp2 = dFdy(vWorld);
    vec2 duv1 = dFdx(uv), duv2 = dFdy(uv);
    vec3 dp2perp = cross(dp2, n), dp1perp = cross(n, dp1);
    vec3 t = dp2perp * duv1.x + dp1perp * duv2.x;
    vec3 b = dp2perp * duv1.y + dp1perp * duv2.y;
    float m = max(dot(t, t), dot(b, b));
    if (m <= 0.0) return n;
    float inv = inversesqrt(m);
    tn.xy *= uNormalStrength;
    return normalize(mat3(t * inv, b * inv, n) * tn);
}

vec3 mappedNormal(vec3 n, vec3 w) {
    if (uHasUv != 0) return perturbed(n, vUv, texture(uNormalMap, vUv).xyz * 2.0 - 1.0);
    vec3 p = vRest * uTilesPerMetre;
    vec3 r = w.x * perturbed(n, p.yz, texture(uNormalMap, p.yz).xyz * 2.0 - 1.0) +
             w.y * perturbed(n, p.xz, texture(uNormalMap, p.xz).xyz * 2.0 - 1.0) +
             w.z * perturbed(n, p.xy, texture(uNormalMap, p.xy).xyz * 2.0 - 1.0);
    return length(r) > 0.0 ? normalize(r) : n;
}

void main() {
    if (uScreenDoor != 0 && ((int(gl_FragCoord.x) + int(gl_FragCoord.y)) & 1) == 0) discard;
    vec3 n = normalize(vNormal);
    if (uDoubleSided != 0 && !gl_FrontFacing) n = -n;

    // Layer masks on the rest position, so the pattern is carried by the deforming tissue.
    float granule = smoothstep(0.45, 0.8, valueNoise(vRest * uLayerFrequency.y));
    vec3 q = vRest * uLayerFrequency.z;
    q += uFibreAxis * (dot(q, uFibreAxis) * -0.85); // stretch cells along the fibre axis
    float fibre = pow(max(1.0 - abs(2.0 * valueNoise(q) - 1.0), 0.0), 6.0);
    float ridge = 1.0 - abs(2.0 * fbm2(vRest * uLayerFrequency.w) - 1.0);
    float thickness = uHasThicknessMap != 0 ? texture(uThicknessMap, vUv).r * uThicknessRange : vThickness;
    float thin = 1.0 - clamp(thickness / (0.5 * uThicknessRange), 0.0, 1.0);
    float vessel = smoothstep(0.9, 0.975, ridge) * mix(0.45, 1.0, thin);

    vec3 diffuse = uSurfaceColour * uLayerWeights.x;
    diffuse = mix(diffuse, uGranularColour, uLayerWeights.y * granule);
    diffuse = mix(diffuse, uConnectiveColour, uLayerWeights.z * fibre);
    diffuse = mix(diffuse, uSubmucosaColour, uLayerWeights.w * vessel);
    float roughness = clamp(uRoughness + uGranularRoughness * (granule - 0.5), 0.04, 1.0);
    float metallic = uMetallic;
    if (uMapMask != 0) {
        vec3 w = triplanarWeights();
        if ((uMapMask & 1) != 0) diffuse = sampleMap(uDiffuseMap, w).rgb;
        if ((uMapMask & 2) != 0) roughness = clamp(sampleMap(uRoughnessMap, w).r, 0.04, 1.0);
        if ((uMapMask & 4) != 0) metallic = sampleMap(uMetallicMap, w).r;
        if ((uMapMask & 8) != 0) n = mappedNormal(n, w);
    }
    diffuse = mix(diffuse, vOverlay.rgb, clamp(vOverlay.a, 0.0, 1.0)); // authoring overlay

    vec2 ndc = vClip.xy / vClip.w, prevNdc = vPrevClip.xy / vPrevClip.w;
    vec2 velocity = clamp(0.5 + 4.0 * 0.5 * (ndc - prevNdc), 0.0, 1.0);

    oG0 = vec4(encodeNormal(n), vViewDepth, uMaterialId);
    oG1 = vec4(roughness, metallic, clamp(thickness / uThicknessRange, 0.0, 1.0), uReflection);
    oG2 = vec4(clamp(diffuse, 0.0, 1.0), clamp(vHeat, 0.0, 1.0));
    oG3 = vec4(velocity, vSamples / 255.0, uFlags / 255.0);
}
