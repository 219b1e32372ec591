#ifndef DERMIS_SSG_BLUR_GLSL
#define DERMIS_SSG_BLUR_GLSL
#include "shader_constants.glsl"
// One 1D Gaussian of the sum-of-Gaussians chain (Listing 4.1) at pixel p: 7
// taps spaced by one standard deviation, scaled per pixel by the stretch
// factors. Shared by the fragment path (ssg_horizontal.frag,
// ssg_vertical.frag) and the compute path (ssg_tiles_*.comp). Taps take
// level 0 explicitly (the images have one): a compute shader has no
// implicit derivatives.
vec4 ssgBlurAt(ivec2 p, vec4 colorM) {
    float depth = COUNTED(SITE(0, 1, FK_POINT), texelFetch(depthTex, p, 0)).r;
    ivec2 axis = pc.dir.x > 0.5 ? ivec2(1, 0) : ivec2(0, 1);
    float stepPx = stretch(p, axis, depth, colorM.a) * pc.stdMm / 3.0;
    vec2 uv = (vec2(p) + 0.5) * pc.texel;
    vec2 stepUv = pc.dir * stepPx * pc.texel;
    const float w[7] = float[](LISTING_4_1_WEIGHT_0, LISTING_4_1_WEIGHT_1, LISTING_4_1_WEIGHT_2,
        LISTING_4_1_WEIGHT_3, LISTING_4_1_WEIGHT_4, LISTING_4_1_WEIGHT_5, LISTING_4_1_WEIGHT_6);
    vec3 acc = vec3(0.0);
    for (int k = -3; k <= 3; k++) {
        acc += w[k + 3] * COUNTED(SITE(0, 0, FK_BILINEAR), textureLod(sampler2D(colorTex, linearClamp), uv + float(k) * stepUv, 0.0)).rgb;
    }
    return vec4(acc, colorM.a);
}

#ifndef SSG_COMPUTE
// The fragment path: stencil- and depth-tested (the Gaussian's LOD), or with
// the thesis' alternative to the stencil test, a dynamic branch on the mask.
layout(early_fragment_tests) in;
vec4 ssgBlur() {
    COUNT_INVOCATION();
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec4 colorM = COUNTED(SITE(0, 0, FK_POINT), texelFetch(colorTex, p, 0));
    if (pc.maskBranch != 0 && colorM.a <= 0.0) discard;
    return ssgBlurAt(p, colorM);
}
#endif
#endif
