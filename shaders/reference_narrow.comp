#version 450
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_GOOGLE_include_directive : require
// Ground truth, the narrow part: Gaussians 1-3 of the profile summed over the
// supersampled visible skin surface within 4 sigma_3, through tissue only, each
// normalised by its weights (src/reference/narrow.rs; the CPU reference in
// src/reference/cpu.rs mirrors this). Writes every pixel: skin gets the narrow
// part (the gather passes add the wide part), other pixels the diffuse light.
#include "fetch_count.glsl"
#include "shader_constants.glsl"
#include "view_scale.glsl"
layout(local_size_x = COMPUTE_GROUP_SIDE, local_size_y = COMPUTE_GROUP_SIDE) in;
layout(set = 0, binding = 0) uniform texture2D diffuseTex;   // alpha = SSS strength
layout(set = 0, binding = 1) uniform texture2D depthTex;     // linear view depth
layout(set = 0, binding = 2, rgba32f) uniform writeonly image2D outImage;
layout(set = 0, binding = 3) uniform texture2D surfRadiance;
layout(set = 0, binding = 4) uniform texture2D surfPosition;  // xyz, w: area (mm^2), 0: none
layout(set = 0, binding = 5) uniform texture2D surfNormal;
layout(set = 0, binding = 6) uniform NarrowParams {
    mat4 invView;
    vec4 view;      // x: tan(fovy/2), y: aspect, z: mm per unit, w: tissue tolerance
    uvec4 surface;  // x: subsamples per pixel per axis, y: largest window radius
} params;

// Variances (mm^2) and RGB weights of the profile's narrow Gaussians (thesis Table 4.2).
const float V[NARROW_GAUSSIANS] = NARROW_VARIANCES_MM2;
const vec3 W[NARROW_GAUSSIANS] = NARROW_WEIGHTS;
const float SIGMA3 = NARROW_LAST_SIGMA_MM;  // the widest narrow Gaussian's sigma

#define TISSUE_MM_PER_UNIT params.view.z
#define TISSUE_TOLERANCE_VALUE params.view.w
#include "tissue.glsl"

void main() {
    COUNT_INVOCATION();
    ivec2 size = textureSize(diffuseTex, 0);
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= size.x || p.y >= size.y) return;
    vec4 d0 = COUNTED(SITE(0, 0, FK_POINT), texelFetch(diffuseTex, p, 0));
    if (d0.a <= 0.0) {
        imageStore(outImage, p, d0);
        return;
    }
    float z = COUNTED(SITE(0, 1, FK_POINT), texelFetch(depthTex, p, 0)).r;
    vec2 ndc = (vec2(p) + 0.5) / vec2(size) * 2.0 - 1.0;
    vec3 viewPos = vec3(ndc.x * params.view.x * params.view.y * z, -ndc.y * params.view.x * z, -z);
    vec3 xo = (params.invView * vec4(viewPos, 1.0)).xyz;
    int s = int(params.surface.x);
    ivec2 c = p * s + s / 2;
    ivec2 ssize = textureSize(surfPosition, 0);
    vec3 no = COUNTED(SITE(0, 5, FK_POINT), texelFetch(surfNormal, c, 0)).xyz;
    // The pixel's SSS strength t scales the profile's radius (thesis eq.
    // 4.3-4.4: R_t(r) = R(r / t) / t^2): distances are measured in units of
    // t mm. Areas cancel in the normalised sums; the tissue test keeps real mm.
    float mm = params.view.z / d0.a;
    float pxPerMm = PX_PER_MM(float(size.y), z, params.view.x, mm);
    int r = int(min(max(ceil(4.0 * SIGMA3 * pxPerMm * float(s)), 1.0), float(params.surface.y)));
    vec3 sum[NARROW_GAUSSIANS] = vec3[](vec3(0.0), vec3(0.0), vec3(0.0));
    float norm[NARROW_GAUSSIANS] = float[](0.0, 0.0, 0.0);
    for (int qy = c.y - r; qy <= c.y + r; qy++) {
        for (int qx = c.x - r; qx <= c.x + r; qx++) {
            ivec2 q = ivec2(qx, qy);
            if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, ssize))) continue;
            vec4 pa = COUNTED(SITE(0, 4, FK_POINT), texelFetch(surfPosition, q, 0));
            if (pa.w <= 0.0) continue;
            vec3 nq = COUNTED(SITE(0, 5, FK_POINT), texelFetch(surfNormal, q, 0)).xyz;
            if (!throughTissue(xo, no, pa.xyz, nq)) continue;
            vec3 dv = (pa.xyz - xo) * mm;
            float r2 = dot(dv, dv);
            vec3 L = COUNTED(SITE(0, 3, FK_POINT), texelFetch(surfRadiance, q, 0)).rgb;
            for (int g = 0; g < NARROW_GAUSSIANS; g++) {
                float e = exp(-r2 / (2.0 * V[g])) * pa.w;
                norm[g] += e;
                sum[g] += e * L;
            }
        }
    }
    vec3 Lc = COUNTED(SITE(0, 3, FK_POINT), texelFetch(surfRadiance, c, 0)).rgb;
    vec3 acc = vec3(0.0);
    for (int g = 0; g < NARROW_GAUSSIANS; g++) {
        acc += W[g] * (norm[g] > 0.0 ? sum[g] / norm[g] : Lc);
    }
    imageStore(outImage, p, vec4(acc, d0.a));
}
