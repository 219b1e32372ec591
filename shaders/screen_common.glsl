#ifndef DERMIS_SCREEN_COMMON_GLSL
#define DERMIS_SCREEN_COMMON_GLSL
#include "fetch_count.glsl"
// Shared by the chapter-4 screen-space passes (ssg, ss-jittered): sources,
// push constants and the stretch factors of thesis eq. 4.1-4.4.
layout(set = 0, binding = 0) uniform texture2D colorTex;  // RGBA16F, alpha = SSS strength
layout(set = 0, binding = 1) uniform texture2D depthTex;  // linear view depth, scene units
layout(set = 0, binding = 2) uniform sampler linearClamp;

layout(push_constant) uniform Push {
    vec2 dir;         // ssg: (1,0) horizontal, (0,1) vertical
    vec2 texel;       // 1 / target size
    float alpha;      // stretch alpha, beta, gamma (scaled to the view)
    float beta;
    float gamma;
    float stdMm;      // ssg: incremental standard deviation of this Gaussian (mm)
    float quadDepth;  // ssg: LOD depth of the full-screen triangle (1 = no LOD)
    int maskBranch;   // ssg: 1 = skip non-skin by a branch instead of the stencil test
    uint code;        // the compute path: the group's stencil code
    float pad1;
    vec4 center;      // ss-jittered kernel: rgb weights
    vec4 mid;         // rgb total of the 6 mid samples
    vec4 wide;        // x: red total of the 6 wide samples, y: mid radius mm, z: wide radius mm
} pc;

// Central depth difference along `axis`, from texel fetches (not ddx: quad
// derivatives are undefined where the stencil cuts a quad, and a CPU can't
// reproduce them).
float depthGradient(ivec2 p, ivec2 axis) {
    ivec2 hi = textureSize(depthTex, 0) - 1;
    float a = COUNTED(SITE(0, 1, FK_POINT), texelFetch(depthTex, clamp(p + axis, ivec2(0), hi), 0)).r;
    float b = COUNTED(SITE(0, 1, FK_POINT), texelFetch(depthTex, clamp(p - axis, ivec2(0), hi), 0)).r;
    return 0.5 * (a - b);
}

// Eq. 4.1/4.2, times the per-pixel strength (eq. 4.3/4.4).
float stretch(ivec2 p, ivec2 axis, float depth, float strength) {
    float g = depthGradient(p, axis);
    return pc.alpha / (depth + pc.beta * min(abs(g), pc.gamma)) * strength;
}
#endif
