#version 450
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_GOOGLE_include_directive : require
// Ground truth, last step: adds the wide Gaussians 4-6 to the narrow part, each
// as its accumulated radiance over its accumulated weight (reference_gather.comp),
// times its RGB weight (thesis Table 4.2).
#include "fetch_count.glsl"
#include "shader_constants.glsl"
layout(local_size_x = COMPUTE_GROUP_SIDE, local_size_y = COMPUTE_GROUP_SIDE) in;
layout(set = 0, binding = 0) uniform texture2D diffuseTex;  // alpha = SSS strength
layout(set = 0, binding = 1, rgba32f) uniform image2D outImage;
layout(set = 0, binding = 2, rgba32f) uniform readonly image2D accum4;
layout(set = 0, binding = 3, rgba32f) uniform readonly image2D accum5;
layout(set = 0, binding = 4, rgba32f) uniform readonly image2D accum6;
const vec3 W[WIDE_GAUSSIANS] = WIDE_WEIGHTS;
void main() {
    COUNT_INVOCATION();
    ivec2 size = textureSize(diffuseTex, 0);
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= size.x || p.y >= size.y) return;
    vec4 d0 = COUNTED(SITE(0, 0, FK_POINT), texelFetch(diffuseTex, p, 0));
    if (d0.a <= 0.0) return;
    vec4 acc[WIDE_GAUSSIANS] = vec4[](imageLoad(accum4, p), imageLoad(accum5, p), imageLoad(accum6, p));
    vec3 m = imageLoad(outImage, p).rgb;
    for (int g = 0; g < WIDE_GAUSSIANS; g++) {
        // No weight reached the pixel (a strength so small the profile is
        // narrower than the samples' spacing): its own light, as the narrow
        // part falls back to.
        m += W[g] * (acc[g].a > 0.0 ? acc[g].rgb / acc[g].a : d0.rgb);
    }
    imageStore(outImage, p, vec4(m, d0.a));
}
