#version 450
#extension GL_GOOGLE_include_directive : require
// Ground truth, the narrow part's input: the visible skin surface at s x the
// frame's resolution. Each subsample: its diffuse radiance (the geometry pass's
// own shading code, no transmittance), its world position and the surface area
// it covers (mm^2), and its normal (src/reference/narrow.rs says why).
#include "lighting.glsl"
layout(location = 0) in vec3 vWorldPos;
layout(location = 1) in vec3 vNormal;
layout(location = 2) in vec4 vTangent;
layout(location = 3) in vec2 vUv;
layout(location = 4) in float vViewDepth;
// model (vertex stage), then: mm of surface per subsample per unit of view
// depth, and the character's wrinkle zone weights.
layout(push_constant) uniform Push { mat4 model; float mmPerSubsamplePerDepth; vec4 zones[2]; } pc;
layout(location = 0) out vec4 outRadiance;
layout(location = 1) out vec4 outPosition;
layout(location = 2) out vec4 outNormal;
// Grazing subsamples cover more surface, up to this many times a facing one.
const float MAX_GRAZING = 20.0;
void main() {
    COUNT_INVOCATION();
    vec3 Nv = normalize(vNormal);
    vec3 N = shadingNormal(Nv, vTangent, vUv, pc.zones);
    float shadow = shadowPcf(vWorldPos, Nv);
    outRadiance = vec4(diffuseLight(scatteredAlbedo(albedoAt(vUv)), N, shadow), 1.0);
    // The subsample's footprint on the surface: its side at this depth, over
    // the cosine between the (flat) surface and the view ray.
    vec3 geo = normalize(cross(dFdx(vWorldPos), dFdy(vWorldPos)));
    vec3 V = normalize(frame.cameraPos.xyz - vWorldPos);
    float side = pc.mmPerSubsamplePerDepth * vViewDepth;
    float area = side * side / max(abs(dot(geo, V)), 1.0 / MAX_GRAZING);
    outPosition = vec4(vWorldPos, area);
    outNormal = vec4(Nv, 0.0);
}
