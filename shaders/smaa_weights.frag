#version 450
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_GOOGLE_include_directive : require
#include "fetch_count.glsl"
// SMAA 1x pass 2 (thesis ch. 10.4.2; the structure of SMAA.hlsl's
// SMAABlendingWeightCalculationPS, its preset's steps and switches pushed by
// src/post/smaa.rs, written here in pixel units):
// per top edgel, first the diagonal patterns (two diagonal searches each way,
// their crossing edges, the diagonal half of the area texture); if none, the
// horizontal line: searches of four edgels per bilinear fetch (at -0.25,
// -0.125 from a pixel centre, Eq. 10.5) decoded at their end by the search
// texture (src/aa/smaa_search.rs), the crossing edges a quarter pixel across,
// the orthogonal area at sqrt(distance) (src/aa/smaa_area.rs, bilinear), and
// sharp corners kept by rounding (Eqs. 10.2, 10.3, 25 %). Then the same for the
// left edgel, vertically (a pixel whose top edgel found a diagonal skips it).
// Stencil-tested: only pixels with an edgel run it.
layout(early_fragment_tests) in;
layout(set = 0, binding = 0) uniform texture2D edgesTex;   // .r left, .g top
layout(set = 0, binding = 1) uniform texture2D areaTex;    // 160 x 560, .rg
layout(set = 0, binding = 2) uniform texture2D searchTex;  // 64 x 16, .r
layout(set = 0, binding = 3) uniform sampler linearClamp;
layout(location = 0) in vec2 vUv;
layout(location = 0) out vec4 outWeights;

// The preset (aa::edges::Preset): orthogonal search steps (16 at high),
// diagonal ones (8; 0: no diagonal patterns, low and medium), the corner
// rounding (0.25) and whether corners are detected at all (not at low and
// medium).
layout(push_constant) uniform Push {
    int maxSearchSteps;
    int maxSearchStepsDiag;
    float cornerRounding;
    int corners;
} pc;
// The area texture's layout (src/aa/smaa_area.rs).
const float AREA_MAX_DISTANCE = 16.0;
const float AREA_MAX_DISTANCE_DIAG = 20.0;
const vec2 AREA_SIZE = vec2(160.0, 560.0);

vec2 size;

// A bilinear fetch of the edges at a position in pixels.
vec2 edgesAt(vec2 pixel) {
    return COUNTED(SITE(0, 0, FK_BILINEAR), textureLod(sampler2D(edgesTex, linearClamp), pixel / size, 0.0)).rg;
}

// SMAASearchLength: how many pixels of the last fetch's pair still belong to
// the line (0, 1, 2), decoded by the search texture (texel as
// smaa_search::texel addresses it, point-sampled, clamped).
float searchLength(vec2 e, float offset) {
    vec2 t = vec2(32.0, -32.0) * e + vec2(66.0 * offset + 0.5, 32.5);
    ivec2 q = clamp(ivec2(floor(t)), ivec2(0), ivec2(63, 15));
    return COUNTED(SITE(0, 2, FK_POINT), texelFetch(searchTex, q, 0)).r;
}

// Each search returns the centre (pixels) of the line's last pixel that way.
float searchXLeft(vec2 at, float end) {
    vec2 e = vec2(0.0, 1.0);
    while (at.x > end && e.g > 0.8281 && e.r == 0.0) {
        e = edgesAt(at);
        at.x -= 2.0;
    }
    float offset = 3.25 - (255.0 / 127.0) * searchLength(e, 0.0);
    return at.x + offset;
}

float searchXRight(vec2 at, float end) {
    vec2 e = vec2(0.0, 1.0);
    while (at.x < end && e.g > 0.8281 && e.r == 0.0) {
        e = edgesAt(at);
        at.x += 2.0;
    }
    float offset = 3.25 - (255.0 / 127.0) * searchLength(e, 0.5);
    return at.x - offset;
}

float searchYUp(vec2 at, float end) {
    vec2 e = vec2(1.0, 0.0);
    while (at.y > end && e.r > 0.8281 && e.g == 0.0) {
        e = edgesAt(at);
        at.y -= 2.0;
    }
    float offset = 3.25 - (255.0 / 127.0) * searchLength(e.gr, 0.0);
    return at.y + offset;
}

float searchYDown(vec2 at, float end) {
    vec2 e = vec2(1.0, 0.0);
    while (at.y < end && e.r > 0.8281 && e.g == 0.0) {
        e = edgesAt(at);
        at.y += 2.0;
    }
    float offset = 3.25 - (255.0 / 127.0) * searchLength(e.gr, 0.5);
    return at.y - offset;
}

// SMAAArea: the orthogonal areas at sqrt(distance), crossing codes round(4 e).
vec2 area(vec2 sqrtD, float e1, float e2) {
    vec2 t = AREA_MAX_DISTANCE * round(4.0 * vec2(e1, e2)) + sqrtD;
    vec2 uv = (t + 0.5) / AREA_SIZE;
    return COUNTED(SITE(0, 1, FK_BILINEAR), textureLod(sampler2D(areaTex, linearClamp), uv, 0.0)).rg;
}

// SMAAAreaDiag: the right half of the texture, linear distances.
vec2 areaDiag(vec2 d, vec2 e) {
    vec2 t = AREA_MAX_DISTANCE_DIAG * e + d;
    vec2 uv = (t + 0.5) / AREA_SIZE + vec2(0.5, 0.0);
    return COUNTED(SITE(0, 1, FK_BILINEAR), textureLod(sampler2D(areaTex, linearClamp), uv, 0.0)).rg;
}

// A fetch a quarter pixel right of a centre reads 0.75 x + 0.25 of the next
// pixel's left edgel: undo that in .r (and .b).
vec2 decodeDiag(vec2 e) {
    e.r = e.r * abs(5.0 * e.r - 5.0 * 0.75);
    return round(e);
}

vec4 decodeDiag4(vec4 e) {
    e.rb = e.rb * abs(5.0 * e.rb - 5.0 * 0.75);
    return round(e);
}

// The diagonal searches: steps along `dir` while both edgels of the next
// pixel are set; (steps, whether the last pixel still had both).
vec2 searchDiag1(vec2 centre, vec2 dir, out vec2 e) {
    vec4 c = vec4(centre, -1.0, 1.0);
    e = vec2(0.0);
    while (c.z < float(pc.maxSearchStepsDiag - 1) && c.w > 0.9) {
        c.xyz += vec3(dir, 1.0);
        e = edgesAt(c.xy);
        c.w = dot(e, vec2(0.5));
    }
    return c.zw;
}

vec2 searchDiag2(vec2 centre, vec2 dir, out vec2 e) {
    vec4 c = vec4(centre, -1.0, 1.0);
    c.x += 0.25;
    e = vec2(0.0);
    while (c.z < float(pc.maxSearchStepsDiag - 1) && c.w > 0.9) {
        c.xyz += vec3(dir, 1.0);
        e = decodeDiag(edgesAt(c.xy));
        c.w = dot(e, vec2(0.5));
    }
    return c.zw;
}

vec2 diagWeights(vec2 centre, vec2 e) {
    vec2 weights = vec2(0.0);
    vec4 d;
    vec2 end;
    // The diagonal rising to the right (down-left, up-right).
    if (e.r > 0.0) {
        d.xz = searchDiag1(centre, vec2(-1.0, 1.0), end);
        d.x += float(end.y > 0.9);
    } else {
        d.xz = vec2(0.0);
    }
    d.yw = searchDiag1(centre, vec2(1.0, -1.0), end);
    if (d.x + d.y > 2.0) {
        vec4 coords = vec4(-d.x + 0.25, d.x, d.y, -d.y - 0.25) + centre.xyxy;
        vec4 c;
        c.xy = edgesAt(coords.xy + vec2(-1.0, 0.0));
        c.zw = edgesAt(coords.zw + vec2(1.0, 0.0));
        c.yxwz = decodeDiag4(c.xyzw);
        vec2 cc = 2.0 * c.xz + c.yw;
        cc = mix(cc, vec2(0.0), bvec2(step(0.9, d.zw)));
        weights += areaDiag(d.xy, cc);
    }
    // The diagonal falling to the right (up-left, down-right).
    d.xz = searchDiag2(centre, vec2(-1.0, -1.0), end);
    if (edgesAt(centre + vec2(1.0, 0.0)).r > 0.0) {
        d.yw = searchDiag2(centre, vec2(1.0, 1.0), end);
        d.y += float(end.y > 0.9);
    } else {
        d.yw = vec2(0.0);
    }
    if (d.x + d.y > 2.0) {
        vec4 coords = vec4(-d.x, -d.x, d.y, d.y) + centre.xyxy;
        vec4 c;
        c.x = edgesAt(coords.xy + vec2(-1.0, 0.0)).g;
        c.y = edgesAt(coords.xy + vec2(0.0, -1.0)).r;
        c.zw = edgesAt(coords.zw + vec2(1.0, 0.0)).gr;
        vec2 cc = 2.0 * c.xz + c.yw;
        cc = mix(cc, vec2(0.0), bvec2(step(0.9, d.zw)));
        weights += areaDiag(d.xy, cc).gr;
    }
    return weights;
}

// Sharp corners (Eqs. 10.2, 10.3): where a crossing edge continues past the
// line's end on one side, that side's blend is rounded down by 1 - r.
vec2 horizontalCorners(vec2 weights, vec4 ends, vec2 d) {
    vec2 leftRight = step(d.xy, d.yx);
    vec2 rounding = (1.0 - pc.cornerRounding) * leftRight;
    rounding /= leftRight.x + leftRight.y;
    vec2 factor = vec2(1.0);
    factor.x -= rounding.x * edgesAt(ends.xy + vec2(0.0, 1.0)).r;
    factor.x -= rounding.y * edgesAt(ends.zw + vec2(1.0, 1.0)).r;
    factor.y -= rounding.x * edgesAt(ends.xy + vec2(0.0, -2.0)).r;
    factor.y -= rounding.y * edgesAt(ends.zw + vec2(1.0, -2.0)).r;
    return weights * clamp(factor, 0.0, 1.0);
}

vec2 verticalCorners(vec2 weights, vec4 ends, vec2 d) {
    vec2 leftRight = step(d.xy, d.yx);
    vec2 rounding = (1.0 - pc.cornerRounding) * leftRight;
    rounding /= leftRight.x + leftRight.y;
    vec2 factor = vec2(1.0);
    factor.x -= rounding.x * edgesAt(ends.xy + vec2(1.0, 0.0)).g;
    factor.x -= rounding.y * edgesAt(ends.zw + vec2(1.0, 1.0)).g;
    factor.y -= rounding.x * edgesAt(ends.xy + vec2(-2.0, 0.0)).g;
    factor.y -= rounding.y * edgesAt(ends.zw + vec2(-2.0, 1.0)).g;
    return weights * clamp(factor, 0.0, 1.0);
}

void main() {
    COUNT_INVOCATION();
    size = vec2(textureSize(edgesTex, 0));
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec2 centre = vec2(p) + 0.5;
    vec2 e = COUNTED(SITE(0, 0, FK_POINT), texelFetch(edgesTex, p, 0)).rg;
    vec4 weights = vec4(0.0);
    float reach = 2.0 * float(pc.maxSearchSteps);
    if (e.g > 0.0) {  // edge at north
        if (pc.maxSearchStepsDiag > 0) {
            weights.rg = diagWeights(centre, e);
        }
        if (weights.r == -weights.g) {  // no diagonal: both zero
            vec2 start = centre + vec2(-0.25, -0.125);
            float left = searchXLeft(start, start.x - reach);
            float e1 = edgesAt(vec2(left, centre.y - 0.25)).r;
            vec2 startR = centre + vec2(1.25, -0.125);
            float right = searchXRight(startR, startR.x + reach);
            float e2 = edgesAt(vec2(right + 1.0, centre.y - 0.25)).r;
            vec2 d = abs(round(vec2(left, right) - centre.x));
            weights.rg = area(sqrt(d), e1, e2);
            if (pc.corners != 0) {
                weights.rg = horizontalCorners(weights.rg, vec4(left, centre.y, right, centre.y), d);
            }
        } else {
            e.r = 0.0;  // a diagonal was found: skip the vertical line
        }
    }
    if (e.r > 0.0) {  // edge at west
        vec2 start = centre + vec2(-0.125, -0.25);
        float up = searchYUp(start, start.y - reach);
        float e1 = edgesAt(vec2(centre.x - 0.25, up)).g;
        vec2 startD = centre + vec2(-0.125, 1.25);
        float down = searchYDown(startD, startD.y + reach);
        float e2 = edgesAt(vec2(centre.x - 0.25, down + 1.0)).g;
        vec2 d = abs(round(vec2(up, down) - centre.y));
        weights.ba = area(sqrt(d), e1, e2);
        if (pc.corners != 0) {
            weights.ba = verticalCorners(weights.ba, vec4(centre.x, up, centre.x, down), d);
        }
    }
    outWeights = weights;
}
