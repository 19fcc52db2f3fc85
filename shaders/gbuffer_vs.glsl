// G-buffer fill [A Fig. 7.4]: per-vertex world position (current and previous frame for velocity),
// normal, rest position (pattern space), baked thickness, painted light samples, heat and the
// authoring overlay (RGBA, blended over the diffuse colour by its alpha; zero when unused) and the
// texture coordinates of the material maps (zero when the mesh has none).
layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec3 aPrevPosition;
layout(location = 2) in vec3 aNormal;
layout(location = 3) in float aHeat;
layout(location = 4) in vec4 aRestThickness;
layout(location = 5) in float aSamples;
layout(location = 6) in vec4 aOverlay;
layout(location = 7) in vec2 aUv;

uniform mat4 uViewProj;
uniform mat4 uPrevViewProj;
uniform mat4 uView;

out vec3 vNormal;
out vec3 vRest;
out float vThickness;
out float vSamples;
out float vHeat;
out vec4 vOverlay;
out vec2 vUv;
out vec3 vWorld;
out vec4 vClip;
out vec4 vPrevClip;
out float vViewDepth;

void main() {
    vNormal = aNormal;
    vRest = aRestThickness.xyz;
    vThickness = aRestThickness.w;
    vSamples = aSamples;
    vHeat = aHeat;
    vOverlay = aOverlay;
    vUv = aUv;
    vWorld = aPosition;
    vClip = uViewProj * vec4(aPosition, 1.0);
    vPrevClip = uPrevViewProj * vec4(aPrevPosition, 1.0);
    vViewDepth = -(uView * vec4(aPosition, 1.0)).z;
    gl_Position = vClip;
}
