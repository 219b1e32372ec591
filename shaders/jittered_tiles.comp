#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
// SS Jittered on the compute path: one workgroup per listed skin tile
// (tiles_classify.comp), one invocation a pixel, the arithmetic of
// jittered_body.glsl. The rings are rotated per pixel, so neighbours share
// texels only where the rings are about a pixel wide: the taps go through
// the texture units (with their cache) rather than a shared-memory apron
// that would have to hold the widest ring around the tile. Reads the
// diffuse target, writes the intermediate at skin pixels (merged back by
// tiles_merge.comp).
#include "shader_constants.glsl"
layout(local_size_x = SSS_TILE_SIDE, local_size_y = SSS_TILE_SIDE) in;
#include "screen_common.glsl"
layout(set = 0, binding = 3) uniform utexture2D stencilTex;
layout(std430, set = 0, binding = 4) readonly buffer Tiles { uint tiles[]; };
layout(set = 0, binding = 5, rgba16f) uniform writeonly image2D outImage;
#include "jittered_body.glsl"

void main() {
    COUNT_INVOCATION();
    uint t = tiles[gl_WorkGroupID.x];
    ivec2 p = ivec2(t & 0xffffu, t >> 16) * SSS_TILE_SIDE + ivec2(gl_LocalInvocationID.xy);
    ivec2 size = textureSize(colorTex, 0);
    if (p.x >= size.x || p.y >= size.y) return;
    if (COUNTED(SITE(0, 3, FK_POINT), texelFetch(stencilTex, p, 0)).r != pc.code) return;
    imageStore(outImage, p, jitteredSss(p));
}
