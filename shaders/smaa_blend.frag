#version 450
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_GOOGLE_include_directive : require
#include "fetch_count.glsl"
// SMAA 1x pass 3 (thesis ch. 10.4; SMAA.hlsl's SMAANeighborhoodBlendingPS):
// every pixel reads its own top and left weights and its right and bottom
// neighbours' opposite ones; the larger pair (horizontal lines or vertical
// ones) decides, and two bilinear fetches offset by the weights blend it
// (linear light: the frame is sRGB). Full screen: every pixel is written.
layout(set = 0, binding = 0) uniform texture2D colorTex;    // tone-mapped frame, sRGB
layout(set = 0, binding = 1) uniform texture2D weightsTex;  // pass 2's weights
layout(set = 0, binding = 2) uniform sampler linearClamp;
// The frame's (and the weights') last texel, pushed: a size query is a
// texture-unit instruction on NVIDIA (docs/perf/issue28/floors.md).
layout(push_constant) uniform Push { ivec2 last; } pc;
layout(location = 0) in vec2 vUv;
layout(location = 0) out vec4 outColor;

void main() {
    COUNT_INVOCATION();
    ivec2 p = ivec2(gl_FragCoord.xy);
    ivec2 last = pc.last;
    vec2 size = vec2(last + 1);
    vec4 a;
    a.x = COUNTED(SITE(0, 1, FK_POINT), texelFetch(weightsTex, min(p + ivec2(1, 0), last), 0)).a;  // right
    a.y = COUNTED(SITE(0, 1, FK_POINT), texelFetch(weightsTex, min(p + ivec2(0, 1), last), 0)).g;  // bottom
    a.wz = COUNTED(SITE(0, 1, FK_POINT), texelFetch(weightsTex, p, 0)).xz;                        // top, left
    if (dot(a, vec4(1.0)) < 1e-5) {
        outColor = COUNTED(SITE(0, 0, FK_POINT), texelFetch(colorTex, p, 0));
        return;
    }
    bool h = max(a.x, a.z) > max(a.y, a.w);
    vec4 offset = h ? vec4(a.x, 0.0, a.z, 0.0) : vec4(0.0, a.y, 0.0, a.w);
    vec2 weight = h ? a.xz : a.yw;
    weight /= dot(weight, vec2(1.0));
    vec2 centre = vec2(p) + 0.5;
    vec4 coords = vec4(centre + offset.xy, centre - offset.zw) / size.xyxy;
    vec4 color = weight.x * COUNTED(SITE(0, 0, FK_BILINEAR), textureLod(sampler2D(colorTex, linearClamp), coords.xy, 0.0));
    color += weight.y * COUNTED(SITE(0, 0, FK_BILINEAR), textureLod(sampler2D(colorTex, linearClamp), coords.zw, 0.0));
    outColor = color;
}
