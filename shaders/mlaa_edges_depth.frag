#version 450
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_GOOGLE_include_directive : require
#include "fetch_count.glsl"
// MLAA pass 1, depth variant (thesis ch. 9.3, Listing 9.1 as printed): the
// left and top edgels from the frame's linear view depth (scene units; the
// threshold, aa::edges::MLAA_DEPTH_THRESHOLD_MM over the scene's millimetres
// per unit, is a length whatever the distance). As mlaa_edges.frag otherwise:
// a pixel none of whose four boundaries is an edge is discarded, so the
// stencil marks the pixels passes 2 and 3 run on; reads clamp at the border.
layout(set = 0, binding = 0) uniform texture2D depthTex;  // linear view depth, R32F
layout(push_constant) uniform Push { float threshold; ivec2 last; } pc;
// `last` is the input's last texel (textureSize - 1), pushed: a size query per
// fetch is a texture-unit instruction on NVIDIA (docs/perf/issue28/floors.md).
layout(location = 0) in vec2 vUv;
layout(location = 0) out vec4 outEdges;

float depthAt(ivec2 p) {
    ivec2 q = clamp(p, ivec2(0), pc.last);
    return COUNTED(SITE(0, 0, FK_POINT), texelFetch(depthTex, q, 0)).r;
}

void main() {
    COUNT_INVOCATION();
    ivec2 p = ivec2(gl_FragCoord.xy);
    float d = depthAt(p);
    vec4 delta = abs(vec4(d) - vec4(depthAt(p + ivec2(-1, 0)), depthAt(p + ivec2(0, -1)),
                                    depthAt(p + ivec2(1, 0)), depthAt(p + ivec2(0, 1))));
    vec4 edges = step(vec4(pc.threshold), delta);
    if (dot(edges, vec4(1.0)) == 0.0) {
        discard;
    }
    outEdges = vec4(edges.rg, 0.0, 0.0);
}
