#ifndef DERMIS_POST_COMMON_GLSL
#define DERMIS_POST_COMMON_GLSL
// What the anti-aliasing stages of the post chain (src/post/) share. They read
// the tone-mapped frame, an sRGB image: its fetches decode to linear light, and
// the edge tests work on gamma-encoded luma as MLAA and FXAA define them
// (thesis ch. 9.3.1), so the encode is undone here. Blending stays in linear
// light: the bilinear fetches of an sRGB image filter after the decode, and
// the sRGB target encodes again.

// The sRGB transfer function (IEC 61966-2-1), linear -> encoded.
vec3 srgbEncode(vec3 c) {
    vec3 lo = c * 12.92;
    vec3 hi = 1.055 * pow(max(c, vec3(0.0)), vec3(1.0 / 2.4)) - 0.055;
    return mix(hi, lo, lessThanEqual(c, vec3(0.0031308)));
}

// Eq. 9.2's luma of a gamma-encoded colour, as src/aa/edges.rs::luma sums it
// (r first, then g, then b).
float lumaOf(vec3 encoded) {
    return 0.2126 * encoded.r + 0.7152 * encoded.g + 0.0722 * encoded.b;
}
#endif
