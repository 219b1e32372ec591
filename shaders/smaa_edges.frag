#version 450
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_GOOGLE_include_directive : require
#include "fetch_count.glsl"
#include "post_common.glsl"
// SMAA 1x pass 1 (thesis ch. 10.4.1, Eq. 10.1): luma edges of the
// gamma-encoded colour, threshold `pc.threshold`, with local contrast
// adaptation: an edgel is kept only if its delta is at least half the largest
// of the six deltas around the pixel (left, top, right, bottom, and the left
// and top neighbours' own left and top ones: SMAA.hlsl's shared maximum,
// src/aa/edges.rs's LocalContrast::Shared). A pixel with neither a left nor
// a top edgel is discarded before the adaptation, so the stencil (REPLACE)
// marks the pixels the blending-weight pass runs on. Reads clamp at the border.
layout(set = 0, binding = 0) uniform texture2D colorTex;  // tone-mapped frame, its UNORM view: encoded values
layout(push_constant) uniform Push { float threshold; float adaptation; ivec2 last; } pc;
// `last` is the input's last texel (textureSize - 1), pushed: a size query per
// fetch is a texture-unit instruction on NVIDIA (docs/perf/issue28/floors.md).
layout(location = 0) in vec2 vUv;
layout(location = 0) out vec4 outEdges;

float lumaAt(ivec2 p) {
    ivec2 q = clamp(p, ivec2(0), pc.last);
    return lumaOf(COUNTED(SITE(0, 0, FK_POINT), texelFetch(colorTex, q, 0)).rgb);
}

void main() {
    COUNT_INVOCATION();
    ivec2 p = ivec2(gl_FragCoord.xy);
    float l = lumaAt(p);
    float left = lumaAt(p + ivec2(-1, 0));
    float top = lumaAt(p + ivec2(0, -1));
    vec2 delta = abs(vec2(l) - vec2(left, top));
    vec2 edges = step(vec2(pc.threshold), delta);
    if (dot(edges, vec2(1.0)) == 0.0) {
        discard;
    }
    vec2 rb = abs(vec2(l) - vec2(lumaAt(p + ivec2(1, 0)), lumaAt(p + ivec2(0, 1))));
    vec2 far = abs(vec2(left, top) - vec2(lumaAt(p + ivec2(-2, 0)), lumaAt(p + ivec2(0, -2))));
    vec2 m = max(max(delta, rb), far);
    float cmax = max(m.x, m.y);
    edges *= step(vec2(cmax), pc.adaptation * delta);
    outEdges = vec4(edges, 0.0, 0.0);
}
