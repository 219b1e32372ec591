#version 450
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_GOOGLE_include_directive : require
#include "fetch_count.glsl"
// Ground truth, step 2: for every skin pixel, the radiant exitance
// M(x_o) = sum_j L_d(x_j) R(|x_j - x_o|) dA_j over all surface samples within the
// cut-off (true 3D distances, visible or not), R the six-Gaussian profile. The three
// narrowest Gaussians (sigma <= 0.43 mm) are taken as w_i L_d(x_o): the surface is
// locally flat and evenly lit at that scale (src/reference/sampling.rs says why).
// Keep in step with NARROW_GAUSSIANS there.
layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform texture2D diffuseTex;  // L_d(x_o) (no transmittance), alpha = strength
layout(set = 0, binding = 1) uniform texture2D depthTex;    // linear view depth
layout(set = 0, binding = 2, rgba32f) uniform image2D outImage;
// Positions (scene units) and areas (mm^2) of the samples, in grid order.
layout(std430, set = 0, binding = 3) readonly buffer Positions { vec4 positions[]; };
layout(set = 0, binding = 4) uniform texture2D radianceTex;  // sample i at (i % width, i / width)
layout(std430, set = 0, binding = 5) readonly buffer Cells { uint cellStart[]; };
layout(set = 0, binding = 6) uniform GatherParams {
    mat4 invView;
    vec4 gridOrigin;   // xyz; w: cell size (scene units)
    uvec4 gridDims;    // xyz; w: width of the radiance texture
    vec4 view;         // x: tan(fovy/2), y: aspect, z: mm per unit, w: cut-off radius (mm)
} params;
// One row of 3 cells of the 3x3x3 neighbourhood per dispatch (dy, dz in -1..1),
// summed into the output: splitting keeps each invocation's loop count a ninth of
// the whole (llvmpipe cuts shader loops after 65535 iterations). One chunk of the
// samples per dispatch, [first, first + count) in grid order: Positions and
// radianceTex hold that chunk only (binding ranges and image sizes are limited).
layout(push_constant) uniform Push { int dy; int dz; uint first; uint count; } pc;

// Six-Gaussian skin profile (thesis Table 4.2), variances in mm^2.
const vec3 W_NARROW = vec3(0.233 + 0.1 + 0.118, 0.455 + 0.336 + 0.198, 0.649 + 0.344 + 0.0);
const vec3 W3 = vec3(0.118, 0.198, 0.0);
const vec3 W4 = vec3(0.113, 0.007, 0.007);
const vec3 W5 = vec3(0.358, 0.004, 0.0);
const vec3 W6 = vec3(0.078, 0.0, 0.0);
const float TWO_PI = 6.28318530718;

vec3 wideProfile(float r2) {
    return W4 * (exp(-r2 / (2.0 * 0.567)) / (TWO_PI * 0.567)) +
           W5 * (exp(-r2 / (2.0 * 1.99)) / (TWO_PI * 1.99)) +
           W6 * (exp(-r2 / (2.0 * 7.41)) / (TWO_PI * 7.41));
}

void main() {
    COUNT_INVOCATION();
    ivec2 size = textureSize(diffuseTex, 0);
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= size.x || p.y >= size.y) return;
    vec4 d0 = COUNTED(SITE(0, 0, FK_POINT), texelFetch(diffuseTex, p, 0));
    if (d0.a <= 0.0) {
        if (pc.dy == -1 && pc.dz == -1 && pc.first == 0u) imageStore(outImage, p, d0);
        return;
    }
    float z = COUNTED(SITE(0, 1, FK_POINT), texelFetch(depthTex, p, 0)).r;
    vec2 ndc = (vec2(p) + 0.5) / vec2(size) * 2.0 - 1.0;
    vec3 viewPos = vec3(ndc.x * params.view.x * params.view.y * z, -ndc.y * params.view.x * z, -z);
    vec3 xo = (params.invView * vec4(viewPos, 1.0)).xyz;
    float mm = params.view.z;
    float cutoff2 = params.view.w * params.view.w;
    ivec3 c = ivec3(floor((xo - params.gridOrigin.xyz) / params.gridOrigin.w));
    ivec3 dims = ivec3(params.gridDims.xyz);
    // The first slab starts the sum with the analytic narrow part.
    bool first = pc.dy == -1 && pc.dz == -1 && pc.first == 0u;
    vec3 acc = first ? W_NARROW * d0.rgb : imageLoad(outImage, p).rgb;
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
            if (r2 > cutoff2) continue;
            vec3 radiance = COUNTED(SITE(0, 4, FK_POINT), texelFetch(radianceTex, ivec2(k % params.gridDims.w, k / params.gridDims.w), 0)).rgb;
            acc += pa.w * radiance * wideProfile(r2);
        }
    }
    imageStore(outImage, p, vec4(acc, d0.a));
}
