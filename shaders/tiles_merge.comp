#version 450
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_GOOGLE_include_directive : require
// The compute path's merge: over the listed tiles, this group's skin pixels
// of a blur's output (written at those pixels only) into the diffuse target
// (src/method/tiles.rs: why a compute blur that reads the diffuse target
// cannot write it in place).
#include "fetch_count.glsl"
#include "shader_constants.glsl"
layout(local_size_x = SSS_TILE_SIDE, local_size_y = SSS_TILE_SIDE) in;
layout(set = 0, binding = 0) uniform utexture2D stencilTex;
layout(std430, set = 0, binding = 1) readonly buffer Tiles { uint tiles[]; };
layout(set = 0, binding = 2) uniform texture2D srcTex;
layout(set = 0, binding = 3, rgba16f) uniform writeonly image2D outImage;
layout(push_constant) uniform Push { uint code; } pc;

void main() {
    COUNT_INVOCATION();
    uint t = tiles[gl_WorkGroupID.x];
    ivec2 p = ivec2(t & 0xffffu, t >> 16) * SSS_TILE_SIDE + ivec2(gl_LocalInvocationID.xy);
    ivec2 size = textureSize(srcTex, 0);
    if (p.x >= size.x || p.y >= size.y) return;
    if (COUNTED(SITE(0, 0, FK_POINT), texelFetch(stencilTex, p, 0)).r != pc.code) return;
    imageStore(outImage, p, COUNTED(SITE(0, 2, FK_POINT), texelFetch(srcTex, p, 0)));
}
