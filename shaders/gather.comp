#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
// The 2D gather of the exact profile (src/skin/gather.rs has the derivation
// and a CPU mirror of this shader): one workgroup per listed skin tile
// (tiles_classify.comp), one invocation a pixel. The samples follow the
// widest channel's radial CDF (a table), rotated per pixel, so neighbours
// share texels only by chance: the taps go through the texture units with
// their cache (as ss-jittered's), not a shared-memory apron that would have
// to hold the kept-mass radius around the tile. The light is filtered
// bilinearly at the sample where its four texels are this group's skin
// (else the nearest texel's, if it is); the depth and the normal are the nearest texel's, and a
// sample counts only where light reaches the pixel from it through tissue (the ground truth's
// test on the two texels' points and normals, below). Reads the diffuse target, writes the
// intermediate at skin pixels (merged back by tiles_merge.comp).
#include "shader_constants.glsl"
#include "fetch_count.glsl"
#include "view_scale.glsl"
layout(local_size_x = SSS_TILE_SIDE, local_size_y = SSS_TILE_SIDE) in;
layout(set = 0, binding = 0) uniform texture2D colorTex;  // RGBA16F, alpha = SSS strength
layout(set = 0, binding = 1) uniform texture2D depthTex;  // linear view depth, scene units
layout(set = 0, binding = 2) uniform utexture2D stencilTex;
layout(std430, set = 0, binding = 3) readonly buffer Tiles { uint tiles[]; };
layout(set = 0, binding = 4, rgba16f) uniform writeonly image2D outImage;
// The widest channel's radius (mm) at quantiles k / lutSize of the kept mass,
// four to a vec4 (std140 pads a float array to vec4 per element).
layout(set = 0, binding = 5) uniform Lut { vec4 lut[GATHER_LUT_VEC4S]; };
layout(set = 0, binding = 6) uniform sampler linearClamp;
layout(set = 0, binding = 7) uniform sampler nearestClamp;
layout(set = 0, binding = 8) uniform texture2D normalTex;  // RGBA16F, view-space unit normal

layout(push_constant) uniform Push {
    vec4 burleyS;         // xyz: Burley's s per channel (1/mm); w: 1 = Burley, 0 = six Gaussians
    float heightPx;
    float tanHalfFovy;
    float mmPerUnit;
    float maxRadiusMm;    // the table's last radius: the kept mass
    float pixelsPerSample;
    uint budget;
    uint minSamples;
    uint code;            // the group's stencil code
    float goldenAngle;
    uint widest;          // the channel the samples follow
    uint lutSize;         // intervals of the table
    float tissueTolerance; // skin::tissue::TISSUE_TOLERANCE
} pc;

#define TISSUE_MM_PER_UNIT pc.mmPerUnit
#define TISSUE_TOLERANCE_VALUE pc.tissueTolerance
#include "tissue.glsl"

const float PI = 3.14159265358979;

// The profile per channel at r mm (per mm^2; the factors common to every
// channel cancel in the weights, but are kept to match the mirror).
vec3 profile(float r) {
    if (pc.burleyS.w > 0.5) {
        vec3 s = pc.burleyS.xyz;
        return s * (exp(-s * r) + exp(-s * r / 3.0)) / (8.0 * PI * r);
    }
    vec3 sum = vec3(0.0);
#define GAUSS(i) sum += SIX_GAUSSIAN_WEIGHT_##i * (exp(-r * r / (2.0 * SIX_GAUSSIAN_VARIANCE_##i)) / (2.0 * PI * SIX_GAUSSIAN_VARIANCE_##i));
    GAUSS(0) GAUSS(1) GAUSS(2) GAUSS(3) GAUSS(4) GAUSS(5)
#undef GAUSS
    return sum;
}

float lutAt(uint k) {
    return lut[k >> 2u][k & 3u];
}

// Radius of quantile u in [0, 1) of the kept mass, linear in the table.
float radiusAt(float u) {
    float x = u * float(pc.lutSize);
    uint k = min(uint(x), pc.lutSize - 1u);
    float f = x - float(k);
    float a = lutAt(k);
    float b = lutAt(k + 1u);
    return a + (b - a) * f;
}

// HDRP's count rule (skin::gather::sample_count).
uint sampleCount(float radiusPx) {
    if (!(radiusPx >= 1.0)) return 0u;
    float area = PI * radiusPx * radiusPx / pc.pixelsPerSample;
    return clamp(uint(ceil(area)), pc.minSamples, max(pc.budget, pc.minSamples));
}

// Integer hash (skin::jittered::pixel_hash) -> the rotation in [0, 2 pi) (its low 16 bits) and the
// offset within each radius stratum in [0, 1) (its high 16 bits)
// (skin::gather::jitter).
vec2 jitter(uvec2 p) {
    uint h = p.x * 1973u + p.y * 9277u;
    h = (h ^ (h >> 13u)) * 0x5bd1e995u;
    h ^= h >> 15u;
    return vec2(float(h & 0xffffu) / 65536.0 * (2.0 * PI), float(h >> 16u) / 65536.0);
}

// The view-space point at the texel centre `c` (pixels) and linear depth z, as
// the ground truth reconstructs its pixels (reference::mirror::PixelPoint:
// ndc.x t aspect z, -ndc.y t z, -z; aspect = width / height).
vec3 viewPoint(vec2 c, float z, vec2 size) {
    vec2 ndc = c / size * 2.0 - 1.0;
    float t = pc.tanHalfFovy;
    return vec3(ndc.x * t * (size.x / size.y) * z, -ndc.y * t * z, -z);
}

void main() {
    COUNT_INVOCATION();
    uint t = tiles[gl_WorkGroupID.x];
    ivec2 p = ivec2(t & 0xffffu, t >> 16) * SSS_TILE_SIDE + ivec2(gl_LocalInvocationID.xy);
    ivec2 size = textureSize(colorTex, 0);
    if (p.x >= size.x || p.y >= size.y) return;
    if (COUNTED(SITE(0, 2, FK_POINT), texelFetch(stencilTex, p, 0)).r != pc.code) return;
    vec4 centre = COUNTED(SITE(0, 0, FK_POINT), texelFetch(colorTex, p, 0));
    float depth = COUNTED(SITE(0, 1, FK_POINT), texelFetch(depthTex, p, 0)).r;
    float pxPerMm = PX_PER_MM(pc.heightPx, depth, pc.tanHalfFovy, pc.mmPerUnit) * centre.a;
    uint n = sampleCount(pc.maxRadiusMm * pxPerMm);
    if (n == 0u) {
        imageStore(outImage, p, centre);
        return;
    }
    vec3 xo = viewPoint(vec2(p) + 0.5, depth, vec2(size));
    vec3 no = COUNTED(SITE(0, 8, FK_POINT), texelFetch(normalTex, p, 0)).xyz;
    vec2 j = jitter(uvec2(p));
    float theta = j.x;
    vec3 sum = vec3(0.0);
    vec3 wsum = vec3(0.0);
    for (uint k = 0u; k < n; k++) {
        float u = (float(k) + j.y) / float(n);
        float r = max(radiusAt(u), 1e-6);
        float a = theta + float(k) * pc.goldenAngle;
        vec2 off = vec2(cos(a) * r * pxPerMm, sin(a) * r * pxPerMm);
        // Off the screen, the edge texel (as the sampler clamps): dropping
        // those samples would drop the far tail wherever the kernel meets
        // the screen's edge (the card's rows moved 7% less light).
        vec2 at = vec2(p) + 0.5 + off;
        ivec2 qi = clamp(ivec2(floor(at)), ivec2(0), size - 1);
        // The stencil codes of the 2x2 texels a bilinear tap at `at` reads
        // (one gather, the footprint's cost).
        uvec4 codes = COUNTED(SITE(0, 2, FK_BILINEAR), textureGather(usampler2D(stencilTex, nearestClamp), at / vec2(size), 0));
        vec3 c;
        if (all(equal(codes, uvec4(pc.code)))) {
            // Bilinear at the sample's own position: a tap at d moves a
            // step's light by exactly d, where the nearest texel moves
            // round(d) (green's and blue's light crossed the card's edge
            // 3-6% short: their taps under half a pixel moved nothing).
            c = COUNTED(SITE(0, 0, FK_BILINEAR), textureLod(sampler2D(colorTex, linearClamp), at / vec2(size), 0.0)).rgb;
        } else {
            // At the skin's edge the footprint holds other texels (the
            // backdrop, another group): the nearest texel alone, if it is
            // this group's skin (bilinear there bled the backdrop into the
            // silhouette: err/none 11.8 in its band at 320x180).
            if (COUNTED(SITE(0, 2, FK_POINT), texelFetch(stencilTex, qi, 0)).r != pc.code) continue;
            c = COUNTED(SITE(0, 0, FK_POINT), texelFetch(colorTex, qi, 0)).rgb;
        }
        float zq = COUNTED(SITE(0, 1, FK_POINT), texelFetch(depthTex, qi, 0)).r;
        // The ground truth's definition of which surface light reaches the
        // pixel from (skin/tissue.rs): only through tissue, each point
        // on or behind the other's tangent plane (within the tolerance).
        // Across a fold (a lip seam, an eyelid on the eye, a silhouette in
        // front of skin whose normal faces it) the two points sit in front
        // of each other's planes: the light crosses air, and the depth
        // weight alone keeps it where both lie at one depth. A binary test,
        // not a cosine weight: a cosine would also dim convex skin (a nose's
        // sides, an ear lit through), which the truth keeps whole.
        vec3 nq = COUNTED(SITE(0, 8, FK_POINT), texelFetch(normalTex, qi, 0)).xyz;
        if (!throughTissue(xo, no, viewPoint(vec2(qi) + 0.5, zq, vec2(size)), nq)) continue;
        float dz = (zq - depth) * pc.mmPerUnit;
        float r3 = sqrt(r * r + dz * dz);
        vec3 w = profile(r3) / profile(r)[pc.widest];
        sum += w * c;
        wsum += w;
    }
    vec3 outRgb = centre.rgb;
    for (int c = 0; c < 3; c++) {
        if (wsum[c] > 0.0) outRgb[c] = sum[c] / wsum[c];
    }
    imageStore(outImage, p, vec4(outRgb, centre.a));
}
