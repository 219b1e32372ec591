#version 450
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_GOOGLE_include_directive : require
#include "fetch_count.glsl"
#include "shader_constants.glsl"
// Ground truth, the wide part: for every skin pixel and each of the profile's
// Gaussians 4-6, accumulates sum_j L_d(x_j) G_i(|x_j - x_o|) dA_j (rgb) and
// sum_j G_i(|x_j - x_o|) dA_j (alpha) over all surface samples within the cut-off
// that light reaches through tissue (true 3D distances, visible or not;
// src/skin/tissue.rs). reference_resolve.comp divides one by the other
// (each Gaussian conserves the light it gathers; src/reference/narrow.rs says
// why) and adds them to the narrow part. The split comes from NARROW_GAUSSIANS
// (src/shader_constants.rs).
layout(local_size_x = COMPUTE_GROUP_SIDE, local_size_y = COMPUTE_GROUP_SIDE) in;
layout(set = 0, binding = 0) uniform texture2D diffuseTex;  // L_d(x_o) (no transmittance), alpha = strength
layout(set = 0, binding = 1) uniform texture2D depthTex;    // linear view depth
layout(set = 0, binding = 2, rgba32f) uniform image2D accum4;
// Positions (scene units) and areas (mm^2) of the samples, in grid order.
layout(std430, set = 0, binding = 3) readonly buffer Positions { vec4 positions[]; };
layout(set = 0, binding = 4) uniform texture2D radianceTex;  // sample i at (i % width, i / width)
layout(std430, set = 0, binding = 5) readonly buffer Cells { uint cellStart[]; };
layout(set = 0, binding = 6) uniform GatherParams {
    mat4 invView;
    vec4 gridOrigin;   // xyz; w: cell size (scene units)
    uvec4 gridDims;    // xyz; w: width of the radiance texture
    vec4 view;         // x: tan(fovy/2), y: aspect, z: mm per unit, w: cut-off radius (mm)
    vec4 tissue;       // x: tissue tolerance; y: subsamples per pixel per axis
} params;
// Normals of the samples, in grid order (this chunk's).
layout(std430, set = 0, binding = 7) readonly buffer Normals { vec4 normals[]; };
layout(set = 0, binding = 8) uniform texture2D surfNormal;  // the supersampled surface's normals
layout(set = 0, binding = 9, rgba32f) uniform image2D accum5;
layout(set = 0, binding = 10, rgba32f) uniform image2D accum6;
// One row of 3 cells of the 3x3x3 neighbourhood per dispatch (dy, dz in -1..1),
// summed into the output: splitting keeps each invocation's loop count a ninth of
// the whole (llvmpipe cuts shader loops after 65535 iterations). One chunk of the
// samples per dispatch, [first, first + count) in grid order: Positions and
// radianceTex hold that chunk only (binding ranges and image sizes are limited).
layout(push_constant) uniform Push { int dy; int dz; uint first; uint count; } pc;

// Variances (mm^2) of the six-Gaussian profile's Gaussians 4-6 (thesis Table 4.2).
const float V[WIDE_GAUSSIANS] = WIDE_VARIANCES_MM2;
const float TWO_PI = 6.28318530718;

#define TISSUE_MM_PER_UNIT params.view.z
#define TISSUE_TOLERANCE_VALUE params.tissue.x
#include "tissue.glsl"

void main() {
    COUNT_INVOCATION();
    ivec2 size = textureSize(diffuseTex, 0);
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= size.x || p.y >= size.y) return;
    vec4 d0 = COUNTED(SITE(0, 0, FK_POINT), texelFetch(diffuseTex, p, 0));
    // Non-skin pixels hold the diffuse light already (reference_narrow.comp).
    if (d0.a <= 0.0) return;
    float z = COUNTED(SITE(0, 1, FK_POINT), texelFetch(depthTex, p, 0)).r;
    vec2 ndc = (vec2(p) + 0.5) / vec2(size) * 2.0 - 1.0;
    vec3 viewPos = vec3(ndc.x * params.view.x * params.view.y * z, -ndc.y * params.view.x * z, -z);
    vec3 xo = (params.invView * vec4(viewPos, 1.0)).xyz;
    // The pixel's SSS strength t scales the profile's radius (thesis eq.
    // 4.3-4.4: R_t(r) = R(r / t) / t^2): distances are measured in units of
    // t mm. Areas cancel in the normalised sums; the tissue test keeps real mm.
    float mm = params.view.z / d0.a;
    float cutoff2 = params.view.w * params.view.w;
    ivec3 c = ivec3(floor((xo - params.gridOrigin.xyz) / params.gridOrigin.w));
    ivec3 dims = ivec3(params.gridDims.xyz);
    int s = int(params.tissue.y);
    vec3 no = COUNTED(SITE(0, 8, FK_POINT), texelFetch(surfNormal, p * s + s / 2, 0)).xyz;
    vec4 acc[WIDE_GAUSSIANS] = vec4[](imageLoad(accum4, p), imageLoad(accum5, p), imageLoad(accum6, p));
    int dz = pc.dz;
    int dy = pc.dy;
    for (int dx = -1; dx <= 1; dx++) {
        ivec3 q = c + ivec3(dx, dy, dz);
        if (any(lessThan(q, ivec3(0))) || any(greaterThanEqual(q, dims))) continue;
        uint cell = uint((q.z * dims.y + q.y) * dims.x + q.x);
        uint end = min(cellStart[cell + 1u], pc.first + pc.count);
        for (uint j = max(cellStart[cell], pc.first); j < end; j++) {
            uint k = j - pc.first;
            vec4 pa = positions[k];
            vec3 dv = (pa.xyz - xo) * mm;
            float r2 = dot(dv, dv);
            if (r2 > cutoff2 || !throughTissue(xo, no, pa.xyz, normals[k].xyz)) continue;
            vec3 radiance = COUNTED(SITE(0, 4, FK_POINT), texelFetch(radianceTex, ivec2(k % params.gridDims.w, k / params.gridDims.w), 0)).rgb;
            for (int g = 0; g < WIDE_GAUSSIANS; g++) {
                float e = pa.w * exp(-r2 / (2.0 * V[g])) / (TWO_PI * V[g]);
                acc[g] += vec4(e * radiance, e);
            }
        }
    }
    imageStore(accum4, p, acc[0]);
    imageStore(accum5, p, acc[1]);
    imageStore(accum6, p, acc[2]);
}
