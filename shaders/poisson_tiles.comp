#version 450
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_GOOGLE_include_directive : require
// Poisson-disk SSS on the compute path: one workgroup per listed skin tile
// (tiles_classify.comp), one invocation a pixel, the arithmetic of
// poisson_body.glsl. Each pixel picks its own mip level and tap count from
// its radius on screen, so the taps go through the texture units rather
// than a shared-memory apron of one level. Writes the intermediate at skin
// pixels (merged into the diffuse target by tiles_merge.comp).
#include "shader_constants.glsl"
layout(local_size_x = SSS_TILE_SIDE, local_size_y = SSS_TILE_SIDE) in;
#include "poisson_body.glsl"
layout(set = 0, binding = 5) uniform utexture2D stencilTex;
layout(std430, set = 0, binding = 6) readonly buffer Tiles { uint tiles[]; };
layout(set = 0, binding = 7, rgba16f) uniform writeonly image2D outImage;

void main() {
    COUNT_INVOCATION();
    uint t = tiles[gl_WorkGroupID.x];
    ivec2 p = ivec2(t & 0xffffu, t >> 16) * SSS_TILE_SIDE + ivec2(gl_LocalInvocationID.xy);
    ivec2 size = textureSize(colorChain, 0);
    if (p.x >= size.x || p.y >= size.y) return;
    if (COUNTED(SITE(0, 5, FK_POINT), texelFetch(stencilTex, p, 0)).r != pc.code) return;
    imageStore(outImage, p, poissonSss(p));
}
