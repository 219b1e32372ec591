#version 450
#extension GL_GOOGLE_include_directive : require
// Ground truth, step 1: the diffuse radiance (albedo x irradiance, no scattering,
// no transmittance heuristic) of every surface sample, lit by the geometry pass's
// own shading code. One fragment per sample: sample i is texel (i % width, i / width)
// of an RGBA32F target. (A fragment pass, not compute: it keeps the hardware
// depth-compare filter of the frame's shadow test.)
#include "lighting.glsl"
struct Sample {
    vec4 posArea;   // world position (scene units), area represented (mm^2)
    vec4 normal;    // vertex normal
    vec4 tangent;   // tangent, w = handedness
    vec4 uv;        // xy; z: the sample's character (its zone weights' index)
};
layout(std430, set = 0, binding = 6) readonly buffer Samples { Sample samples[]; };
// Each character's wrinkle zone weights, two vec4 (src/reference/sampling.rs).
layout(std430, set = 0, binding = 7) readonly buffer Zones { vec4 zones[]; };
// One chunk of the samples per draw (storage-buffer ranges are limited): this
// draw covers rows firstRow.. of the target and samples first.. of the buffer range.
layout(push_constant) uniform Push { uint count; uint width; uint firstRow; } pc;
layout(location = 0) in vec2 vUv;
layout(location = 0) out vec4 outRadiance;
void main() {
    COUNT_INVOCATION();
    uint i = (uint(gl_FragCoord.y) - pc.firstRow) * pc.width + uint(gl_FragCoord.x);
    if (i >= pc.count) {
        outRadiance = vec4(0.0);
        return;
    }
    Sample s = samples[i];
    vec3 Nv = normalize(s.normal.xyz);
    uint c = uint(s.uv.z + 0.5);
    vec3 N = shadingNormal(Nv, s.tangent, s.uv.xy, vec4[2](zones[2 * c], zones[2 * c + 1]));
    float shadow = shadowPcf(s.posArea.xyz, Nv);
    outRadiance = vec4(diffuseLight(scatteredAlbedo(albedoAt(s.uv.xy)), N, shadow), 0.0);
}
