#version 450
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_GOOGLE_include_directive : require
// The compute path's classification (its early culling, as the stencil test
// is the fragment path's): one workgroup per SSS_TILE_SIDE^2 tile of the
// region's bounding box. List k holds each tile with a pixel of this group's
// stencil code whose depth-buffer value is under maxDepth[k] (ssg's
// depth-based Gaussian skipping, thesis 4.2.1, per tile: the fragment path's
// depth test against the Gaussian's triangle; 2.0 passes every pixel); each
// list's length is the x of its indirect dispatch (src/method/tiles.rs).
#include "fetch_count.glsl"
#include "shader_constants.glsl"
layout(local_size_x = SSS_TILE_SIDE, local_size_y = SSS_TILE_SIDE) in;
layout(set = 0, binding = 0) uniform utexture2D stencilTex;
layout(set = 0, binding = 3) uniform texture2D depthTex;   // the depth aspect
// Per list: x = listed tiles (the dispatch's groups), y = z = 1, w unused.
layout(std430, set = 0, binding = 1) buffer Args { uint args[]; };
// List k's tiles as x | y << 16, from k * capacity.
layout(std430, set = 0, binding = 2) buffer Tiles { uint tiles[]; };
layout(push_constant) uniform Push {
    ivec2 firstTile;   // the region's bounding box, in tiles
    uint code;         // the group's stencil code
    uint lists;        // 1..=SSS_MAX_TILE_LISTS
    uint capacity;     // entries from one list's start to the next
    float maxDepth[SSS_MAX_TILE_LISTS];
} pc;

shared uint inList[SSS_MAX_TILE_LISTS];

void main() {
    COUNT_INVOCATION();
    if (gl_LocalInvocationIndex < uint(SSS_MAX_TILE_LISTS)) inList[gl_LocalInvocationIndex] = 0u;
    barrier();
    ivec2 tile = pc.firstTile + ivec2(gl_WorkGroupID.xy);
    ivec2 p = tile * SSS_TILE_SIDE + ivec2(gl_LocalInvocationID.xy);
    ivec2 size = textureSize(stencilTex, 0);
    if (p.x < size.x && p.y < size.y) {
        uint s = COUNTED(SITE(0, 0, FK_POINT), texelFetch(stencilTex, p, 0)).r;
        if (s == pc.code) {
            float d = COUNTED(SITE(0, 3, FK_POINT), texelFetch(depthTex, p, 0)).r;
            for (uint k = 0u; k < pc.lists; k++) {
                if (d < pc.maxDepth[k]) atomicOr(inList[k], 1u);
            }
        }
    }
    barrier();
    if (gl_LocalInvocationIndex == 0u) {
        for (uint k = 0u; k < pc.lists; k++) {
            if (gl_WorkGroupID.xy == uvec2(0u)) {
                args[4u * k + 1u] = 1u;
                args[4u * k + 2u] = 1u;
            }
            if (inList[k] != 0u) {
                uint i = atomicAdd(args[4u * k], 1u);
                tiles[k * pc.capacity + i] = uint(tile.x) | (uint(tile.y) << 16);
            }
        }
    }
}
