#version 450
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_GOOGLE_include_directive : require
#include "fetch_count.glsl"
// MLAA pass 3 (thesis ch. 9.5, Listing 9.5): blends each pixel with its four
// neighbours by the areas of pass 2: its own top and left edgels' first area
// (it takes colour across them), the bottom neighbour's top edgel's second
// area and the right neighbour's left edgel's second (their colour comes
// in). One bilinear fetch per neighbour, offset by the area, does each
// blend (Eq. 9.1); a pixel on several lines averages them. (The listing names
// its `right` and `bottom` fetches the other way round; the offsets it reads
// are the ones used here.) Stencil-tested: pixels off every edge keep the copy
// of the frame made before this pass.
layout(early_fragment_tests) in;
layout(set = 0, binding = 0) uniform texture2D colorTex;    // tone-mapped frame, sRGB
layout(set = 0, binding = 1) uniform texture2D weightsTex;  // pass 2's areas
layout(set = 0, binding = 2) uniform sampler linearClamp;
// The frame's (and the weights') last texel, pushed: a size query is a
// texture-unit instruction on NVIDIA (docs/perf/issue28/floors.md).
layout(push_constant) uniform Push { ivec2 last; } pc;
layout(location = 0) in vec2 vUv;
layout(location = 0) out vec4 outColor;

vec4 colorAt(vec2 pixel) {
    vec2 uv = pixel / vec2(pc.last + 1);
    return COUNTED(SITE(0, 0, FK_BILINEAR), textureLod(sampler2D(colorTex, linearClamp), uv, 0.0));
}

void main() {
    COUNT_INVOCATION();
    ivec2 p = ivec2(gl_FragCoord.xy);
    ivec2 last = pc.last;
    vec4 topLeft = COUNTED(SITE(0, 1, FK_POINT), texelFetch(weightsTex, p, 0));
    float bottom = COUNTED(SITE(0, 1, FK_POINT), texelFetch(weightsTex, min(p + ivec2(0, 1), last), 0)).g;
    float right = COUNTED(SITE(0, 1, FK_POINT), texelFetch(weightsTex, min(p + ivec2(1, 0), last), 0)).a;
    // North, south, west, east.
    vec4 a = vec4(topLeft.r, bottom, topLeft.b, right);
    float sum = dot(a, vec4(1.0));
    if (sum > 0.0) {
        vec2 centre = vec2(p) + 0.5;
        vec4 color = vec4(0.0);
        color += a.r * colorAt(centre + vec2(0.0, -a.r));
        color += a.g * colorAt(centre + vec2(0.0, a.g));
        color += a.b * colorAt(centre + vec2(-a.b, 0.0));
        color += a.a * colorAt(centre + vec2(a.a, 0.0));
        outColor = color / sum;
    } else {
        outColor = COUNTED(SITE(0, 0, FK_POINT), texelFetch(colorTex, p, 0));
    }
}
