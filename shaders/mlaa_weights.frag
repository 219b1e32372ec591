#version 450
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_GOOGLE_include_directive : require
#include "fetch_count.glsl"
#include "shader_constants.glsl"
// MLAA pass 2 (thesis ch. 9.4, Listings 9.2-9.4): per edgel of this pixel (top
// into .rg, left into .ba), the distances to both ends of its line, two edgels
// per bilinear fetch (9.4.1), the crossing edges at both ends fetched a
// quarter pixel toward the other side of the edge (9.4.2), and the two areas
// from the precomputed area texture (9.4.3, src/aa/mlaa_area.rs, uploaded as
// generated). Stencil-tested: only pixels pass 1 kept run it.
layout(early_fragment_tests) in;
layout(set = 0, binding = 0) uniform texture2D edgesTex;  // .r left, .g top edgel
layout(set = 0, binding = 1) uniform texture2D areaTex;   // 45 x 45, .rg areas
layout(set = 0, binding = 2) uniform sampler linearClamp;
layout(location = 0) in vec2 vUv;
layout(location = 0) out vec4 outWeights;

vec2 edgelsAt(vec2 pixel) {
    vec2 uv = pixel / vec2(textureSize(edgesTex, 0));
    return COUNTED(SITE(0, 0, FK_BILINEAR), textureLod(sampler2D(edgesTex, linearClamp), uv, 0.0)).rg;
}

// Listing 9.3 in pixel units: the distance from the pixel centred at `centre`
// to the end of its line along `dir`, reading channel `c` (0: left edgels,
// 1: top). Each fetch sits between two pixels and reads both; a value under
// 0.9 (1 in exact arithmetic) ends the line, 0.5 one pixel into the pair.
float searchDistance(vec2 centre, vec2 dir, int c) {
    vec2 at = centre + 1.5 * dir;
    float e = 0.0;
    int i;
    for (i = 0; i < MLAA_MAX_SEARCH_STEPS; i++) {
        e = edgelsAt(at)[c];
        if (e < 0.9) {
            break;
        }
        at += 2.0 * dir;
    }
    return min(2.0 * float(i) + 2.0 * e, 2.0 * float(MLAA_MAX_SEARCH_STEPS));
}

// Listing 9.4, with the texel addressed directly: round(4 e) codes the
// crossing edges (0, 1, 3 or 4), the distances pick the texel inside the
// pattern's 9 x 9 subtexture (the same texel as the listing's point-sampled
// pixcoord / 44; src/aa/mlaa_area.rs tests the two agree).
vec2 area(vec2 d, float e1, float e2) {
    vec2 texel = float(MLAA_NUM_DISTANCES) * round(4.0 * vec2(e1, e2)) + round(d);
    return COUNTED(SITE(0, 1, FK_POINT), texelFetch(areaTex, ivec2(texel), 0)).rg;
}

void main() {
    COUNT_INVOCATION();
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec2 centre = vec2(p) + 0.5;
    vec2 e = COUNTED(SITE(0, 0, FK_POINT), texelFetch(edgesTex, p, 0)).rg;
    vec4 weights = vec4(0.0);
    if (e.g > 0.0) {  // edge at north: a horizontal line, searched left and right
        vec2 d = vec2(searchDistance(centre, vec2(-1.0, 0.0), 1),
                      searchDistance(centre, vec2(1.0, 0.0), 1));
        float e1 = edgelsAt(centre + vec2(-round(d.x), -0.25)).r;
        float e2 = edgelsAt(centre + vec2(round(d.y) + 1.0, -0.25)).r;
        weights.rg = area(d, e1, e2);
    }
    if (e.r > 0.0) {  // edge at west: a vertical line, searched up and down
        vec2 d = vec2(searchDistance(centre, vec2(0.0, -1.0), 0),
                      searchDistance(centre, vec2(0.0, 1.0), 0));
        float e1 = edgelsAt(centre + vec2(-0.25, -round(d.x))).g;
        float e2 = edgelsAt(centre + vec2(-0.25, round(d.y) + 1.0)).g;
        weights.ba = area(d, e1, e2);
    }
    outWeights = weights;
}
