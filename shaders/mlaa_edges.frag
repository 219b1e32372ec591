#version 450
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_GOOGLE_include_directive : require
#include "fetch_count.glsl"
#include "post_common.glsl"
// MLAA pass 1 (thesis ch. 9.3.1, Listing 9.1 with Eq. 9.2's luma): the left and
// top edgels of every pixel into .rg. A pixel none of whose four boundaries is
// an edge is discarded, so the stencil (REPLACE on pass) marks exactly the
// pixels passes 2 and 3 must run on. No early fragment tests: a discarded
// fragment must not write the stencil. Reads clamp at the border (as
// src/aa/edges.rs does), so a border pixel never has an edgel toward outside.
layout(set = 0, binding = 0) uniform texture2D colorTex;  // tone-mapped frame, its UNORM view: encoded values
layout(push_constant) uniform Push { float threshold; ivec2 last; } pc;
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
    // Left, top, then the right and bottom ones only for the stencil.
    vec4 delta = abs(vec4(l) - vec4(lumaAt(p + ivec2(-1, 0)), lumaAt(p + ivec2(0, -1)),
                                    lumaAt(p + ivec2(1, 0)), lumaAt(p + ivec2(0, 1))));
    vec4 edges = step(vec4(pc.threshold), delta);
    if (dot(edges, vec4(1.0)) == 0.0) {
        discard;
    }
    outEdges = vec4(edges.rg, 0.0, 0.0);
}
