#version 450
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_GOOGLE_include_directive : require
#include "fetch_count.glsl"
#include "shader_constants.glsl"
// Bloom, the Gaussian of one pyramid level along one axis
// (src/post/bloom_pyramid.rs): 2R + 1 point taps, clamped at the border,
// weights normalised to 1 (so a uniform level stays uniform).
layout(set = 0, binding = 0) uniform texture2D srcTex;
layout(push_constant) uniform Push {
    float weights[BLOOM_BLUR_RADIUS + 1];  // offsets 0..R, the same either side
    ivec2 dir;                             // (1, 0) horizontal, (0, 1) vertical
    ivec2 hi;                              // the level's last texel (size - 1): pushed,
                                           // not queried (see bloom_combine.frag)
} pc;
layout(location = 0) in vec2 vUv;
layout(location = 0) out vec4 outColor;

void main() {
    COUNT_INVOCATION();
    ivec2 p = ivec2(gl_FragCoord.xy);
    ivec2 hi = pc.hi;
    vec4 acc = vec4(0.0);
    for (int i = -BLOOM_BLUR_RADIUS; i <= BLOOM_BLUR_RADIUS; i++) {
        ivec2 q = clamp(p + i * pc.dir, ivec2(0), hi);
        acc += pc.weights[abs(i)] * COUNTED(SITE(0, 0, FK_POINT), texelFetch(srcTex, q, 0));
    }
    outColor = acc;
}
