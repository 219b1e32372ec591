#version 450
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_GOOGLE_include_directive : require
#include "fetch_count.glsl"
// SMAA 1x pass 1, colour variant (thesis ch. 10.4.1; SMAA.hlsl's colour edge
// detection): the delta of two pixels is the largest of their R, G and B
// differences of the gamma-encoded colour (src/aa/edges.rs's
// smaa_color_edges), then as smaa_edges.frag: threshold, discard of pixels
// with neither a left nor a top edgel (the stencil marks the rest), and the
// local contrast adaptation against the largest of the six deltas around.
layout(set = 0, binding = 0) uniform texture2D colorTex;  // tone-mapped frame, its UNORM view: encoded values
layout(push_constant) uniform Push { float threshold; float adaptation; ivec2 last; } pc;
// `last` is the input's last texel (textureSize - 1), pushed: a size query per
// fetch is a texture-unit instruction on NVIDIA (docs/perf/issue28/floors.md).
layout(location = 0) in vec2 vUv;
layout(location = 0) out vec4 outEdges;

vec3 colorAt(ivec2 p) {
    ivec2 q = clamp(p, ivec2(0), pc.last);
    return COUNTED(SITE(0, 0, FK_POINT), texelFetch(colorTex, q, 0)).rgb;
}

float deltaOf(vec3 a, vec3 b) {
    vec3 t = abs(a - b);
    return max(max(t.r, t.g), t.b);
}

void main() {
    COUNT_INVOCATION();
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec3 c = colorAt(p);
    vec3 left = colorAt(p + ivec2(-1, 0));
    vec3 top = colorAt(p + ivec2(0, -1));
    vec2 delta = vec2(deltaOf(c, left), deltaOf(c, top));
    vec2 edges = step(vec2(pc.threshold), delta);
    if (dot(edges, vec2(1.0)) == 0.0) {
        discard;
    }
    vec2 rb = vec2(deltaOf(c, colorAt(p + ivec2(1, 0))), deltaOf(c, colorAt(p + ivec2(0, 1))));
    vec2 far = vec2(deltaOf(left, colorAt(p + ivec2(-2, 0))), deltaOf(top, colorAt(p + ivec2(0, -2))));
    vec2 m = max(max(delta, rb), far);
    float cmax = max(m.x, m.y);
    edges *= step(vec2(cmax), pc.adaptation * delta);
    outEdges = vec4(edges, 0.0, 0.0);
}
