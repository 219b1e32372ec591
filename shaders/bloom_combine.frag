#version 450
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_GOOGLE_include_directive : require
#include "fetch_count.glsl"
#include "shader_constants.glsl"
// Bloom, the last pass (src/post/bloom_pyramid.rs): out = (1 - s) hdr + s B,
// B the levels' weighted sum, each level read back bilinearly at this pixel
// (level k's texel m sits on pixel 2^k m, so the texel coordinate is p / 2^k).
// An energy-conserving mix: a uniform frame stays as it is.
layout(set = 0, binding = 0) uniform texture2D hdrTex;
layout(set = 0, binding = 1) uniform texture2D level1Tex;
layout(set = 0, binding = 2) uniform texture2D level2Tex;
layout(set = 0, binding = 3) uniform texture2D level3Tex;
layout(set = 0, binding = 4) uniform texture2D level4Tex;
layout(set = 0, binding = 5) uniform sampler linearClamp;
// The levels' sizes come with the push constants, not from textureSize: a
// size query is an instruction of the texture unit on NVIDIA (TXQ), and four
// of them per pixel cost this pass more than its four bilinear fetches
// (docs/perf/issue28/floors.md). The values are textureSize's, as floats,
// so every coordinate is what it was.
layout(push_constant) uniform Push {
    vec4 levelWeights;
    vec4 size12;  // level 1's size in xy, level 2's in zw (texels)
    vec4 size34;  // level 3's, level 4's
    float strength;
} pc;
layout(location = 0) in vec2 vUv;
layout(location = 0) out vec4 outColor;

#if BLOOM_LEVELS != 4
#error "bloom_combine.frag binds four levels"
#endif

// Level T at pixel p, T's texel coordinate p * SCALE (a macro: a function
// taking the texture would be one fetch site for four fetches).
#define LEVEL(T, SCALE, SIZE, BINDING, p) COUNTED(SITE(0, BINDING, FK_BILINEAR), \
    texture(sampler2D(T, linearClamp), ((p) * (SCALE) + 0.5) / (SIZE))).rgb

void main() {
    COUNT_INVOCATION();
    ivec2 ip = ivec2(gl_FragCoord.xy);
    vec2 p = vec2(ip);
    vec4 c = COUNTED(SITE(0, 0, FK_POINT), texelFetch(hdrTex, ip, 0));
    vec3 b = pc.levelWeights.x * LEVEL(level1Tex, 0.5, pc.size12.xy, 1, p)
           + pc.levelWeights.y * LEVEL(level2Tex, 0.25, pc.size12.zw, 2, p)
           + pc.levelWeights.z * LEVEL(level3Tex, 0.125, pc.size34.xy, 3, p)
           + pc.levelWeights.w * LEVEL(level4Tex, 0.0625, pc.size34.zw, 4, p);
    outColor = vec4((1.0 - pc.strength) * c.rgb + pc.strength * b, c.a);
}
