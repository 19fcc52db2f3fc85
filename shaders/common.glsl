// Shared helpers, included by the other shaders (#include "common.glsl").
const float PI = 3.14159265358979;

// Octahedral normal encoding into [-1, 1]^2.
vec2 octWrap(vec2 v) { return (1.0 - abs(v.yx)) * vec2(v.x >= 0.0 ? 1.0 : -1.0, v.y >= 0.0 ? 1.0 : -1.0); }
vec2 encodeNormal(vec3 n) {
    n /= abs(n.x) + abs(n.y) + abs(n.z);
    return n.z >= 0.0 ? n.xy : octWrap(n.xy);
}
vec3 decodeNormal(vec2 e) {
    vec3 n = vec3(e, 1.0 - abs(e.x) - abs(e.y));
    float t = clamp(-n.z, 0.0, 1.0);
    n.x += n.x >= 0.0 ? -t : t;
    n.y += n.y >= 0.0 ? -t : t;
    return normalize(n);
}

// Integer hash (deterministic on every implementation).
uint hashU(uint x) {
    x ^= x >> 16u; x *= 0x7feb352du;
    x ^= x >> 15u; x *= 0x846ca68bu;
    x ^= x >> 16u;
    return x;
}
float hash3(ivec3 c) {
    uint h = hashU(uint(c.x) * 73856093u ^ hashU(uint(c.y) * 19349663u ^ hashU(uint(c.z) * 83492791u)));
    return float(h & 0xffffffu) / 16777215.0;
}
// Trilinear value noise in [0, 1].
float valueNoise(vec3 p) {
    vec3 i = floor(p), f = fract(p);
    vec3 u = f * f * (3.0 - 2.0 * f);
    ivec3 c = ivec3(i);
    float n000 = hash3(c), n100 = hash3(c + ivec3(1, 0, 0));
    float n010 = hash3(c + ivec3(0, 1, 0)), n110 = hash3(c + ivec3(1, 1, 0));
    float n001 = hash3(c + ivec3(0, 0, 1)), n101 = hash3(c + ivec3(1, 0, 1));
    float n011 = hash3(c + ivec3(0, 1, 1)), n111 = hash3(c + ivec3(1, 1, 1));
    return mix(mix(mix(n000, n100, u.x), mix(n010, n110, u.x), u.y),
               mix(mix(n001, n101, u.x), mix(n011, n111, u.x), u.y), u.z);
}
float fbm2(vec3 p) { return 0.65 * valueNoise(p) + 0.35 * valueNoise(2.03 * p + 17.0); }

// Display encoding (sRGB transfer curve).
vec3 linearToSrgb(vec3 c) {
    c = clamp(c, 0.0, 1.0);
    return mix(12.92 * c, 1.055 * pow(max(c, vec3(0.0)), vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), c));
}
vec3 srgbToLinear(vec3 c) {
    c = clamp(c, 0.0, 1.0);
    return mix(c / 12.92, pow(max((c + 0.055) / 1.055, vec3(0.0)), vec3(2.4)), step(vec3(0.04045), c));
}
