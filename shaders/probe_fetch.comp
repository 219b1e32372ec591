#version 450
#extension GL_GOOGLE_include_directive : require
#include "fetch_count.glsl"
#include "shader_constants.glsl"
// Ceiling probe on the compute path: probe_fetch.frag's N fetches per
// invocation from one texture (bilinear or point by the bound sampler) at
// sub-texel offsets, one invocation a pixel in SSS_TILE_SIDE-square groups
// as the compute blurs run, each writing one RGBA16F texel of a storage
// image (with N = 0, the store rate alone).
layout(local_size_x = SSS_TILE_SIDE, local_size_y = SSS_TILE_SIDE) in;
layout(set = 0, binding = 0) uniform texture2D srcTex;
layout(set = 0, binding = 1) uniform sampler srcSampler;
layout(set = 0, binding = 2, rgba16f) uniform writeonly image2D outImage;
layout(push_constant) uniform Push { vec2 texel; int taps; int pad; } pc;
void main() {
    COUNT_INVOCATION();
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(outImage);
    if (p.x >= size.x || p.y >= size.y) return;
    vec2 uv = (vec2(p) + 0.5) * pc.texel;
    vec4 acc = vec4(0.0);
    for (int i = 0; i < pc.taps; i++) {
        acc += COUNTED(SITE(0, 0, FK_BILINEAR), textureLod(sampler2D(srcTex, srcSampler), uv + vec2(float(i - pc.taps / 2) * 0.37, 0.25) * pc.texel, 0.0));
    }
    imageStore(outImage, p, acc * (1.0 / float(max(pc.taps, 1))));
}
