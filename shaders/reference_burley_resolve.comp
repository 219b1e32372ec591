#version 450
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_GOOGLE_include_directive : require
// Ground truth of Burley's profile, last step: adds the far part to the near
// part, per channel its accumulated radiance over its accumulated weight
// (reference_burley_gather.comp) times A (1 - F(r_c)). A channel with no far
// sample takes the near part's light for it, so nothing is lost
// (src/reference/burley.rs; mirror.rs's gather_f64_burley does the same).
// Binds the six Gaussians' resolve layout; accum6 is unused.
#include "fetch_count.glsl"
#include "shader_constants.glsl"
#include "reference_burley.glsl"
layout(local_size_x = COMPUTE_GROUP_SIDE, local_size_y = COMPUTE_GROUP_SIDE) in;
layout(set = 0, binding = 0) uniform texture2D diffuseTex;  // alpha = SSS strength
layout(set = 0, binding = 1, rgba32f) uniform image2D outImage;
layout(set = 0, binding = 2, rgba32f) uniform readonly image2D accum4;
layout(set = 0, binding = 3, rgba32f) uniform readonly image2D accum5;
layout(set = 0, binding = 4, rgba32f) uniform readonly image2D accum6;
void main() {
    COUNT_INVOCATION();
    ivec2 size = textureSize(diffuseTex, 0);
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= size.x || p.y >= size.y) return;
    vec4 d0 = COUNTED(SITE(0, 0, FK_POINT), texelFetch(diffuseTex, p, 0));
    if (d0.a <= 0.0) return;
    vec3 sum = imageLoad(accum4, p).rgb;
    vec3 norm = imageLoad(accum5, p).rgb;
    vec3 tail = 0.25 * exp(-BURLEY_S * BURLEY_NEAR_MM) + 0.75 * exp(-BURLEY_S * BURLEY_NEAR_MM / 3.0);
    vec3 nearW = BURLEY_ALBEDO * (1.0 - tail);
    vec3 farW = BURLEY_ALBEDO * tail;
    vec3 near = imageLoad(outImage, p).rgb;
    vec3 far = mix(near / nearW, sum / max(norm, vec3(1e-30)), greaterThan(norm, vec3(0.0)));
    imageStore(outImage, p, vec4(near + farW * far, d0.a));
}
