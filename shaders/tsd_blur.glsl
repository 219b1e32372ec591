#ifndef DERMIS_TSD_BLUR_GLSL
#define DERMIS_TSD_BLUR_GLSL
// Texture-space diffusion: one separable Gaussian pass (Listing 4.1's 7 taps,
// one standard deviation apart, as seed 004's convolveU/convolveV), the step
// scaled by the stretch map. The maps hold premultiplied coverage (rgb * a, a):
// a tap on a texel nobody wrote adds nothing, so dividing by alpha averages
// written texels only (Gosselin's dilation at UV seams, as a normalised
// convolution). Taps stay inside the depth-sized map (texture coordinates
// limited to 0..s, section 3.3).
#extension GL_EXT_samplerless_texture_functions : require
layout(early_fragment_tests) in;
#include "fetch_count.glsl"
#include "shader_constants.glsl"
layout(set = 0, binding = 0) uniform texture2D srcTex;
layout(set = 0, binding = 1) uniform texture2D stretchTex;   // texels per mm along this pass's axis
layout(set = 0, binding = 2) uniform sampler linearClamp;
layout(push_constant) uniform Push {
    vec2 dir;        // (1,0): along u; (0,1): along v
    float stdMm;     // the standard deviation this Gaussian adds (mm)
    float invSize;   // 1 / T_max
    float uvMax;     // largest tap coordinate: (T - 0.5 - 1/512) / T_max
    int alphaTest;   // Listing 3.3: texels with source alpha 0 write 0 and fetch nothing more
} pc;
vec4 tsdBlur() {
    COUNT_INVOCATION();
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec4 c = COUNTED(SITE(0, 0, FK_POINT), texelFetch(srcTex, p, 0));
    if (pc.alphaTest != 0 && c.a <= 0.0) {
        return vec4(0.0);
    }
    float st = COUNTED(SITE(0, 1, FK_POINT), texelFetch(stretchTex, p, 0)).r;
    vec2 uv = (vec2(p) + 0.5) * pc.invSize;
    vec2 stepUv = pc.dir * (st * pc.stdMm * pc.invSize);
    vec2 lo = vec2(0.5 * pc.invSize);
    vec2 hi = vec2(pc.uvMax);
    // Listing 4.1's centre and one side (the weights are symmetric).
    const float w[4] = float[](LISTING_4_1_WEIGHT_3, LISTING_4_1_WEIGHT_4, LISTING_4_1_WEIGHT_5, LISTING_4_1_WEIGHT_6);
    vec4 acc = w[0] * c;
    for (int k = 1; k <= 3; k++) {
        vec2 o = float(k) * stepUv;
        acc += w[k] * COUNTED(SITE(0, 0, FK_BILINEAR), texture(sampler2D(srcTex, linearClamp), clamp(uv - o, lo, hi)));
        acc += w[k] * COUNTED(SITE(0, 0, FK_BILINEAR), texture(sampler2D(srcTex, linearClamp), clamp(uv + o, lo, hi)));
    }
    return acc;
}
#endif
