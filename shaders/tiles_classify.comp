#version 450
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_GOOGLE_include_directive : require
// The compute path's classification (its early culling, as the stencil test
// is the fragment path's): one workgroup per SSS_TILE_SIDE^2 tile of the
// region's bounding box; a tile with at least one pixel of this group's
// stencil code is appended to the tile list, and the list's length is the x
// of the blurs' indirect dispatch (src/method/tiles.rs).
#include "fetch_count.glsl"
#include "shader_constants.glsl"
layout(local_size_x = SSS_TILE_SIDE, local_size_y = SSS_TILE_SIDE) in;
layout(set = 0, binding = 0) uniform utexture2D stencilTex;
// x: listed tiles (the dispatch's groups), y = z = 1; w unused.
layout(std430, set = 0, binding = 1) buffer Args { uint args[4]; };
// Each listed tile as x | y << 16, in tiles.
layout(std430, set = 0, binding = 2) buffer Tiles { uint tiles[]; };
layout(push_constant) uniform Push {
    ivec2 firstTile;   // the region's bounding box, in tiles
    uint code;         // the group's stencil code
} pc;

shared uint anySkin;

void main() {
    COUNT_INVOCATION();
    if (gl_LocalInvocationIndex == 0u) anySkin = 0u;
    barrier();
    ivec2 tile = pc.firstTile + ivec2(gl_WorkGroupID.xy);
    ivec2 p = tile * SSS_TILE_SIDE + ivec2(gl_LocalInvocationID.xy);
    ivec2 size = textureSize(stencilTex, 0);
    if (p.x < size.x && p.y < size.y) {
        uint s = COUNTED(SITE(0, 0, FK_POINT), texelFetch(stencilTex, p, 0)).r;
        if (s == pc.code) atomicOr(anySkin, 1u);
    }
    barrier();
    if (gl_LocalInvocationIndex == 0u) {
        if (gl_WorkGroupID.xy == uvec2(0u)) {
            args[1] = 1u;
            args[2] = 1u;
        }
        if (anySkin != 0u) {
            uint i = atomicAdd(args[0], 1u);
            tiles[i] = uint(tile.x) | (uint(tile.y) << 16);
        }
    }
}
