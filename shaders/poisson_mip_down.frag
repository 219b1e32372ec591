#version 450
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_GOOGLE_include_directive : require
#include "fetch_count.glsl"
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
    COUNT_INVOCATION();
    ivec2 p = ivec2(gl_FragCoord.xy) * 2;
    ivec2 hi = textureSize(srcColor, 0) - 1;
    ivec2 a = at(p, hi), b = at(p + ivec2(1, 0), hi), c = at(p + ivec2(0, 1), hi), d = at(p + ivec2(1, 1), hi);
    outColor = ((COUNTED(SITE(0, 0, FK_POINT), texelFetch(srcColor, a, 0)) + COUNTED(SITE(0, 0, FK_POINT), texelFetch(srcColor, b, 0))) + (COUNTED(SITE(0, 0, FK_POINT), texelFetch(srcColor, c, 0)) + COUNTED(SITE(0, 0, FK_POINT), texelFetch(srcColor, d, 0)))) * 0.25;
    outDepth = ((COUNTED(SITE(0, 1, FK_POINT), texelFetch(srcDepth, a, 0)).r + COUNTED(SITE(0, 1, FK_POINT), texelFetch(srcDepth, b, 0)).r) + (COUNTED(SITE(0, 1, FK_POINT), texelFetch(srcDepth, c, 0)).r + COUNTED(SITE(0, 1, FK_POINT), texelFetch(srcDepth, d, 0)).r)) * 0.25;
    outNormal = ((COUNTED(SITE(0, 2, FK_POINT), texelFetch(srcNormal, a, 0)) + COUNTED(SITE(0, 2, FK_POINT), texelFetch(srcNormal, b, 0))) + (COUNTED(SITE(0, 2, FK_POINT), texelFetch(srcNormal, c, 0)) + COUNTED(SITE(0, 2, FK_POINT), texelFetch(srcNormal, d, 0)))) * 0.25;
}
