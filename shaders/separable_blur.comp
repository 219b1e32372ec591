#version 450
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_GOOGLE_include_directive : require
#include "fetch_count.glsl"
#include "shader_constants.glsl"
#include "view_scale.glsl"
// Separable SSS on the compute path: the arithmetic of separable_blur.frag,
// one workgroup per listed skin tile (tiles_classify.comp), one invocation a pixel.
// The tile and an apron of SSS_APRON_PX texels on both sides along the blur's
// direction are loaded into shared memory once; each tap then filters its two
// neighbouring texels there (beyond the apron, from the images: the same
// texels), in float, at the fraction the sampler computes, in the fragment
// shader's order (src/method/tiles.rs says where the two paths differ).
//
// No seed copy: the vertical pass reads the intermediate at this group's
// skin texels and the diffuse target everywhere else, what the fragment
// path's seeded intermediate holds there; the horizontal pass writes the
// intermediate at skin pixels only.
layout(local_size_x = SSS_TILE_SIDE, local_size_y = SSS_TILE_SIDE) in;

layout(set = 0, binding = 0) uniform texture2D colorTex;   // horizontal: diffuse; vertical: intermediate
layout(set = 0, binding = 1) uniform texture2D depthTex;   // linear view depth, scene units
layout(set = 0, binding = 2) uniform utexture2D stencilTex;
layout(set = 0, binding = 3) uniform KernelUniforms {
    vec4 samples[SEPARABLE_MAX_SAMPLES];   // rgb weight, w: offset in millimetres; [0] is the centre
} kernel;
layout(std430, set = 0, binding = 4) readonly buffer Tiles { uint tiles[]; };
// Horizontal: the intermediate (written at skin pixels); vertical: the
// diffuse target (read at other texels, written at skin pixels).
layout(set = 0, binding = 5, rgba16f) uniform image2D outImage;
layout(push_constant) uniform Push {
    vec2 dir;           // (1,0) horizontal, (0,1) vertical
    float aspect;       // width / height
    float tanHalfFovy;
    float mmPerUnit;
    float followTolMm;  // depth difference (mm) at which a sample is fully replaced
    int nSamples;
    int followSurface;
    uint code;          // the group's stencil code
    int vertical;
} pc;

#define ALONG (SSS_TILE_SIDE + 2 * SSS_APRON_PX)
// Rows one texel longer than they hold: the vertical blur's neighbouring
// invocations read neighbouring rows, and a row of 80 (a multiple of 32
// banks) put all of them on one shared-memory bank (measured on an H200:
// the vertical blur took 2.4x the horizontal's time).
#define ROW (ALONG + 1)
shared uvec2 sColor[SSS_TILE_SIDE * ROW];
shared float sDepth[SSS_TILE_SIDE * ROW];

// Image coordinates of (along the blur, across it).
ivec2 at(int along, int across) {
    return pc.vertical != 0 ? ivec2(across, along) : ivec2(along, across);
}

// What the fragment path's source image holds at in-bounds texel q.
vec4 source(ivec2 q) {
    if (pc.vertical != 0) {
        uint s = COUNTED(SITE(0, 2, FK_POINT), texelFetch(stencilTex, q, 0)).r;
        if (s != pc.code) return imageLoad(outImage, q);
    }
    return COUNTED(SITE(0, 0, FK_POINT), texelFetch(colorTex, q, 0));
}

void main() {
    COUNT_INVOCATION();
    uint t = tiles[gl_WorkGroupID.x];
    ivec2 origin = ivec2(t & 0xffffu, t >> 16) * SSS_TILE_SIDE;
    ivec2 size = textureSize(colorTex, 0);
    int along0 = (pc.vertical != 0 ? origin.y : origin.x) - SSS_APRON_PX;
    int across0 = pc.vertical != 0 ? origin.x : origin.y;
    int alongMax = (pc.vertical != 0 ? size.y : size.x) - 1;
    int acrossMax = (pc.vertical != 0 ? size.x : size.y) - 1;

    // The tile and its apron, clamped to the image as the sampler clamps.
    for (uint i = gl_LocalInvocationIndex; i < uint(SSS_TILE_SIDE * ALONG);
         i += uint(SSS_TILE_SIDE * SSS_TILE_SIDE)) {
        int across = int(i) / ALONG, along = int(i) % ALONG;
        ivec2 q = at(clamp(along0 + along, 0, alongMax), min(across0 + across, acrossMax));
        vec4 v = source(q);
        int slot = across * ROW + along;
        sColor[slot] = uvec2(packHalf2x16(v.rg), packHalf2x16(v.ba));
        sDepth[slot] = COUNTED(SITE(0, 1, FK_POINT), texelFetch(depthTex, q, 0)).r;
    }
    barrier();

    ivec2 lid = ivec2(gl_LocalInvocationID.xy);
    ivec2 p = origin + lid;
    if (p.x >= size.x || p.y >= size.y) return;
    if (COUNTED(SITE(0, 2, FK_POINT), texelFetch(stencilTex, p, 0)).r != pc.code) return;
    int row = (pc.vertical != 0 ? lid.x : lid.y) * ROW;
    int centre = row + SSS_APRON_PX + (pc.vertical != 0 ? lid.y : lid.x);
    vec4 colorM = vec4(unpackHalf2x16(sColor[centre].x), unpackHalf2x16(sColor[centre].y));
    float depthM = sDepth[centre];
    vec2 uv = (vec2(p) + 0.5) / vec2(size);

    // As separable_blur.frag: one millimetre in uv, the same on-screen length
    // in both directions.
    float screenH = SCREEN_HEIGHT_UNITS(depthM, pc.tanHalfFovy);
    vec2 stepPerMm = pc.dir / (pc.mmPerUnit * screenH);
    stepPerMm.x /= pc.aspect;
    vec2 stepUv = stepPerMm * colorM.a;
    float uvAlong = pc.vertical != 0 ? uv.y : uv.x;
    float stepAlong = pc.vertical != 0 ? stepUv.y : stepUv.x;
    float sizeAlong = float(alongMax + 1);
    int across = pc.vertical != 0 ? p.x : p.y;

    vec3 acc = colorM.rgb * kernel.samples[0].rgb;
    for (int i = 1; i < pc.nSamples; i++) {
        vec4 k = kernel.samples[i];
        float x = (uvAlong + k.w * stepAlong) * sizeAlong - 0.5;
        float x0 = floor(x);
        float f = x - x0;
        vec4 c2[2];
        float d2[2];
        for (int j = 0; j < 2; j++) {
            int s = int(x0) + j - along0;
            if (s >= 0 && s < ALONG) {
                uvec2 h = sColor[row + s];
                c2[j] = vec4(unpackHalf2x16(h.x), unpackHalf2x16(h.y));
                d2[j] = sDepth[row + s];
            } else {
                // Beyond the apron (a kernel wider than SSS_APRON_PX on
                // screen): the same texel from the images.
                ivec2 q = at(clamp(int(x0) + j, 0, alongMax), across);
                c2[j] = source(q);
                d2[j] = COUNTED(SITE(0, 1, FK_POINT), texelFetch(depthTex, q, 0)).r;
            }
        }
        vec3 c = c2[0].rgb * (1.0 - f) + c2[1].rgb * f;
        if (pc.followSurface != 0) {
            // Follow the surface: a sample across a depth step larger than the
            // kernel is replaced by the centre colour.
            float d = d2[0] * (1.0 - f) + d2[1] * f;
            float s = clamp(abs(depthM - d) * pc.mmPerUnit / pc.followTolMm, 0.0, 1.0);
            c = c + (colorM.rgb - c) * s;
        }
        acc += k.rgb * c;
    }
    imageStore(outImage, p, vec4(acc, colorM.a));
}
