#ifndef DERMIS_TSD_CHARACTER_GLSL
#define DERMIS_TSD_CHARACTER_GLSL
#include "shader_constants.glsl"
// Texture-space diffusion (method/tsd.rs): what every UV-space draw of one
// character reads. Set 2 (sets 0 and 1 are lighting.glsl's frame and material).
layout(set = 2, binding = 0) uniform CharacterUniforms {
    mat4 model;
    vec4 planes[6];   // world-space clip planes (eq. 3.4); (0,0,0,1) when clipping is off
    vec4 params;      // x: s (eq. 3.1), y: SSS strength, z: cull cosine (Listing 3.2; -2: off)
    vec4 mapInfo;     // x: 1 / T_max, y: largest tap coordinate (see tsd_blur.glsl)
    vec4 zones[2];    // the character's wrinkle zone weights (lighting.glsl's wrinkleSlope)
} ch;
// The atlas: per UV island, atlas = uv * x + yz (skin::tsd_ref::Atlas). A
// vertex's island is encoded in its tangent's w: sign(w) (1 + island).
layout(set = 2, binding = 1) uniform AtlasUniforms { vec4 islands[TSD_MAX_ISLANDS]; } atlas;
layout(push_constant) uniform TsdPush {
    float z;          // depth the draw writes or tests (0: kept, 1: culled)
    float threshold;  // tsd_mask.frag: the eye-dot threshold
    float keepAbove;  // tsd_mask.frag: 1 keeps texels at or above it, 0 those below
} pc;
#endif
