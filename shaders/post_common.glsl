#ifndef DERMIS_POST_COMMON_GLSL
#define DERMIS_POST_COMMON_GLSL
// What the anti-aliasing stages of the post chain (src/post/) share. The edge
// tests work on the luma of the gamma-encoded colour, as MLAA, SMAA and FXAA
// define them (thesis ch. 9.3.1, 10.4.1): their passes read the tone-mapped
// frame through a UNORM view of its sRGB image, i.e. its encoded bytes with no
// decode. Blending reads the sRGB view instead, so it happens in linear light
// (the bilinear fetches filter after the decode, the sRGB target encodes).

// Eq. 9.2's luma of a gamma-encoded colour, as src/aa/edges.rs::luma sums it
// (r first, then g, then b).
float lumaOf(vec3 encoded) {
    return 0.2126 * encoded.r + 0.7152 * encoded.g + 0.0722 * encoded.b;
}
#endif
