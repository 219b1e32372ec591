#version 450
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_GOOGLE_include_directive : require
#include "fetch_count.glsl"
#include "post_common.glsl"
// FXAA, quality preset (Lottes' FXAA 3.11 "quality" algorithm, preset 12),
// written from its description, one pass over the tone-mapped frame:
// 1. luma (Eq. 9.2, gamma-encoded) of the pixel and its 4-neighbourhood; a
//    local contrast under max(EDGE_MIN, EDGE_REL * max luma) leaves the pixel
//    as it is;
// 2. the 3x3 neighbourhood decides the edge's orientation (second
//    differences across rows against across columns) and its side (the
//    steeper neighbour across it);
// 3. a search along the edge, both ways, on the boundary between the pixel and
//    that neighbour (bilinear fetches there read both rows at once), with
//    growing steps, stops where the luma leaves the boundary's average by a
//    quarter of the gradient;
// 4. the nearer end, if its luma turns the way the pixel's does, gives the
//    offset toward the neighbour (0.5 at the end, 0 at the middle of the
//    span); a sub-pixel term (the pixel against its 3x3 low-pass) can raise
//    it; one bilinear fetch at that offset is the result.
layout(set = 0, binding = 0) uniform texture2D colorTex;  // tone-mapped frame, sRGB: fetches decode
layout(set = 0, binding = 1) uniform sampler linearClamp;
layout(set = 0, binding = 2) uniform texture2D lumaTex;   // the same, its UNORM view: encoded values
layout(location = 0) in vec2 vUv;
layout(location = 0) out vec4 outColor;

// The quality preset's knobs (FXAA 3.11 defaults).
const float EDGE_REL = 0.166;   // fxaaQualityEdgeThreshold
const float EDGE_MIN = 0.0833;  // fxaaQualityEdgeThresholdMin
const float SUBPIX = 0.75;      // fxaaQualitySubpix
// Preset 12: five steps, the last ones long.
const int STEPS = 5;
const float STEP_LENGTH[STEPS] = float[](1.0, 1.5, 2.0, 4.0, 12.0);

ivec2 lastTexel;
// The frame's last texel (its size - 1), pushed: a size query is a
// texture-unit instruction on NVIDIA (docs/perf/issue28/floors.md).
layout(push_constant) uniform Push { ivec2 last; } pc;

float lumaAtTexel(ivec2 p) {
    ivec2 q = clamp(p, ivec2(0), lastTexel);
    return lumaOf(COUNTED(SITE(0, 2, FK_POINT), texelFetch(lumaTex, q, 0)).rgb);
}

// Luma between texels: a bilinear fetch of the encoded values (FXAA filters
// in gamma space).
float lumaAt(vec2 pixel) {
    vec2 uv = pixel / vec2(lastTexel + 1);
    return lumaOf(COUNTED(SITE(0, 2, FK_BILINEAR), textureLod(sampler2D(lumaTex, linearClamp), uv, 0.0)).rgb);
}

void main() {
    COUNT_INVOCATION();
    lastTexel = pc.last;
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec4 colorM = COUNTED(SITE(0, 0, FK_POINT), texelFetch(colorTex, p, 0));
    float m = lumaAtTexel(p);
    float n = lumaAtTexel(p + ivec2(0, -1));
    float s = lumaAtTexel(p + ivec2(0, 1));
    float w = lumaAtTexel(p + ivec2(-1, 0));
    float e = lumaAtTexel(p + ivec2(1, 0));
    float hi = max(max(max(n, s), max(w, e)), m);
    float lo = min(min(min(n, s), min(w, e)), m);
    float range = hi - lo;
    if (range < max(EDGE_MIN, hi * EDGE_REL)) {
        outColor = colorM;
        return;
    }
    float nw = lumaAtTexel(p + ivec2(-1, -1));
    float ne = lumaAtTexel(p + ivec2(1, -1));
    float sw = lumaAtTexel(p + ivec2(-1, 1));
    float se = lumaAtTexel(p + ivec2(1, 1));

    // Sub-pixel aliasing: the pixel against its neighbourhood's low-pass.
    float lowPass = (2.0 * (n + s + w + e) + (nw + ne + sw + se)) / 12.0;
    float a = clamp(abs(lowPass - m) / range, 0.0, 1.0);
    float b = (-2.0 * a + 3.0) * a * a;
    float subpix = b * b * SUBPIX;

    // A horizontal edge changes across rows: second differences down the columns.
    float acrossRows = abs(nw - 2.0 * w + sw) + 2.0 * abs(n - 2.0 * m + s) + abs(ne - 2.0 * e + se);
    float acrossCols = abs(nw - 2.0 * n + ne) + 2.0 * abs(w - 2.0 * m + e) + abs(sw - 2.0 * s + se);
    bool horizontal = acrossRows >= acrossCols;
    // The side: toward the steeper neighbour across the edge.
    float before = horizontal ? n : w;
    float after = horizontal ? s : e;
    float gradBefore = abs(before - m);
    float gradAfter = abs(after - m);
    bool toBefore = gradBefore >= gradAfter;
    float side = toBefore ? -1.0 : 1.0;
    float lumaEdge = 0.5 * (m + (toBefore ? before : after));
    float gradient = 0.25 * max(gradBefore, gradAfter);

    vec2 across = horizontal ? vec2(0.0, 1.0) : vec2(1.0, 0.0);
    vec2 along = horizontal ? vec2(1.0, 0.0) : vec2(0.0, 1.0);
    vec2 centre = vec2(p) + 0.5;
    vec2 boundary = centre + 0.5 * side * across;

    // Search both ways until the luma leaves the boundary's average.
    vec2 posN = boundary;
    vec2 posP = boundary;
    float endN = 0.0;
    float endP = 0.0;
    bool doneN = false;
    bool doneP = false;
    for (int i = 0; i < STEPS; i++) {
        if (!doneN) {
            posN -= STEP_LENGTH[i] * along;
            endN = lumaAt(posN) - lumaEdge;
            doneN = abs(endN) >= gradient;
        }
        if (!doneP) {
            posP += STEP_LENGTH[i] * along;
            endP = lumaAt(posP) - lumaEdge;
            doneP = abs(endP) >= gradient;
        }
        if (doneN && doneP) {
            break;
        }
    }
    float distN = dot(boundary - posN, along);
    float distP = dot(posP - boundary, along);
    bool nearerN = distN < distP;
    float dist = min(distN, distP);
    float span = distN + distP;
    // The nearer end counts only if its luma turns away from the pixel's.
    bool mBelow = (m - lumaEdge) < 0.0;
    bool good = ((nearerN ? endN : endP) < 0.0) != mBelow;
    float offset = good ? 0.5 - dist / span : 0.0;
    offset = max(offset, subpix);
    vec2 uv = (centre + offset * side * across) / vec2(lastTexel + 1);
    outColor = COUNTED(SITE(0, 0, FK_BILINEAR), textureLod(sampler2D(colorTex, linearClamp), uv, 0.0));
}
