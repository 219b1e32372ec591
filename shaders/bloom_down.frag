#version 450
#extension GL_GOOGLE_include_directive : require
#include "fetch_count.glsl"
// Bloom, one reduction of the pyramid (src/post/bloom_pyramid.rs): texel m of
// this level sits on texel 2m of the level below (sample-centred), and is
// [1, 2, 1] / 4 of texels 2m - 1, 2m, 2m + 1 on each axis. Four bilinear
// fetches half a texel off the centre give that 3 x 3 tent exactly (their
// weights are halves); the clamp-to-edge sampler repeats the border texel, as
// the CPU mirror does.
layout(set = 0, binding = 0) uniform texture2D srcTex;
layout(set = 0, binding = 1) uniform sampler linearClamp;
// The source's size in texels (textureSize's, as floats): pushed, not
// queried, since a size query costs a texture-unit instruction per pixel on
// NVIDIA (see bloom_combine.frag).
layout(push_constant) uniform Push { vec2 srcSize; } pc;
layout(location = 0) in vec2 vUv;
layout(location = 0) out vec4 outColor;

vec4 at(vec2 texel, vec2 size) {
    return COUNTED(SITE(0, 0, FK_BILINEAR), texture(sampler2D(srcTex, linearClamp), texel / size));
}

void main() {
    COUNT_INVOCATION();
    vec2 size = pc.srcSize;
    // The centre of texel 2m below, in texel units (centres at i + 0.5).
    vec2 c = 2.0 * floor(gl_FragCoord.xy) + 0.5;
    vec4 s = (at(c + vec2(-0.5, -0.5), size) + at(c + vec2(0.5, -0.5), size))
           + (at(c + vec2(-0.5, 0.5), size) + at(c + vec2(0.5, 0.5), size));
    outColor = 0.25 * s;
}
