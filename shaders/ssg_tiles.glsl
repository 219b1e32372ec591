#ifndef DERMIS_SSG_TILES_GLSL
#define DERMIS_SSG_TILES_GLSL
// ssg on the compute path: one workgroup per tile of this Gaussian's list
// (tiles_classify.comp lists the skin tiles holding a surface nearer than
// the Gaussian's LOD depth: the fragment path's depth test, per tile), one
// invocation a pixel, the arithmetic of ssg_blur.glsl through the same
// sampler. A pixel runs where the fragment path's pixel passes its stencil
// and depth tests: this group's code, and a depth-buffer value under the
// Gaussian's triangle's (pc.quadDepth, test GREATER).
#define SSG_COMPUTE
#include "shader_constants.glsl"
layout(local_size_x = SSS_TILE_SIDE, local_size_y = SSS_TILE_SIDE) in;
#include "screen_common.glsl"
layout(set = 0, binding = 3) uniform utexture2D stencilTex;
layout(set = 0, binding = 4) uniform texture2D dsDepthTex;   // the depth aspect
layout(std430, set = 0, binding = 5) readonly buffer Tiles { uint tiles[]; };
layout(set = 0, binding = 6, rgba16f) uniform writeonly image2D outImage;
#include "ssg_blur.glsl"

// The pixel this invocation blurs, if it is one the fragment path shades.
bool ssgPixel(out ivec2 p) {
    uint t = tiles[gl_WorkGroupID.x];
    p = ivec2(t & 0xffffu, t >> 16) * SSS_TILE_SIDE + ivec2(gl_LocalInvocationID.xy);
    ivec2 size = textureSize(colorTex, 0);
    if (p.x >= size.x || p.y >= size.y) return false;
    if (COUNTED(SITE(0, 3, FK_POINT), texelFetch(stencilTex, p, 0)).r != pc.code) return false;
    return pc.quadDepth > COUNTED(SITE(0, 4, FK_POINT), texelFetch(dsDepthTex, p, 0)).r;
}
#endif
