#version 450
#extension GL_GOOGLE_include_directive : require
#include "fetch_count.glsl"
#include "shader_constants.glsl"
// Ceiling probe (bench::ceilings): shared-memory bandwidth on the compute
// path, in the compute blurs' SSS_TILE_SIDE-square groups. Each invocation
// stores its texel of the source into shared memory, then reads N 16-byte
// slots back: the invocations of a warp read consecutive slots (no bank
// conflict), a different neighbour each tap, so no read is a repeat the
// compiler could drop. One RGBA16F store each, as probe_fetch.comp.
layout(local_size_x = SSS_TILE_SIDE, local_size_y = SSS_TILE_SIDE) in;
layout(set = 0, binding = 0) uniform texture2D srcTex;
layout(set = 0, binding = 1) uniform sampler srcSampler;
layout(set = 0, binding = 2, rgba16f) uniform writeonly image2D outImage;
layout(push_constant) uniform Push { vec2 texel; int taps; int pad; } pc;
#define GROUP (SSS_TILE_SIDE * SSS_TILE_SIDE)
shared vec4 sTile[GROUP];
void main() {
    COUNT_INVOCATION();
    uint me = gl_LocalInvocationIndex;
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(outImage);
    ivec2 q = min(p, size - 1);
    sTile[me] = COUNTED(SITE(0, 0, FK_POINT), texelFetch(sampler2D(srcTex, srcSampler), q, 0));
    barrier();
    vec4 acc = vec4(0.0);
    for (int i = 1; i <= pc.taps; i++) {
        acc += sTile[(me + uint(i) * 17u) % uint(GROUP)];
    }
    if (p.x < size.x && p.y < size.y) {
        imageStore(outImage, p, acc * (1.0 / float(max(pc.taps, 1))));
    }
}
