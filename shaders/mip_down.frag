#version 450
#extension GL_EXT_samplerless_texture_functions : require
// One level of the poisson method's mip chains: each texel is the mean of the
// 2x2 texels under it (edge texels repeat on odd sizes), for colour, depth and
// normal at once.
layout(set = 0, binding = 0) uniform texture2D srcColor;
layout(set = 0, binding = 1) uniform texture2D srcDepth;
layout(set = 0, binding = 2) uniform texture2D srcNormal;
layout(location = 0) in vec2 vUv;
layout(location = 0) out vec4 outColor;
layout(location = 1) out float outDepth;
layout(location = 2) out vec4 outNormal;

ivec2 at(ivec2 p, ivec2 hi) { return min(p, hi); }

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy) * 2;
    ivec2 hi = textureSize(srcColor, 0) - 1;
    ivec2 a = at(p, hi), b = at(p + ivec2(1, 0), hi), c = at(p + ivec2(0, 1), hi), d = at(p + ivec2(1, 1), hi);
    outColor = ((texelFetch(srcColor, a, 0) + texelFetch(srcColor, b, 0)) + (texelFetch(srcColor, c, 0) + texelFetch(srcColor, d, 0))) * 0.25;
    outDepth = ((texelFetch(srcDepth, a, 0).r + texelFetch(srcDepth, b, 0).r) + (texelFetch(srcDepth, c, 0).r + texelFetch(srcDepth, d, 0).r)) * 0.25;
    outNormal = ((texelFetch(srcNormal, a, 0) + texelFetch(srcNormal, b, 0)) + (texelFetch(srcNormal, c, 0) + texelFetch(srcNormal, d, 0))) * 0.25;
}
