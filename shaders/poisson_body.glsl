#ifndef DERMIS_POISSON_BODY_GLSL
#define DERMIS_POISSON_BODY_GLSL
#include "fetch_count.glsl"
// Poisson-disk screen-space SSS (Agni's Philosophy, seed 003) for one pixel,
// shared by the fragment path (poisson.frag) and the compute path
// (poisson_tiles.comp): 32 disk samples weighted by distance to the centre
// (per channel), depth difference and normal difference, fetched from a mip
// level chosen by the radius; fewer samples when the radius is small on
// screen (far objects).
layout(set = 0, binding = 0) uniform texture2D colorChain;   // RGBA16F mips, alpha = strength
layout(set = 0, binding = 1) uniform texture2D depthChain;   // R32F mips, linear depth
layout(set = 0, binding = 2) uniform texture2D normalChain;  // RGBA16F mips, view-space normal
layout(set = 0, binding = 3) uniform sampler mipClamp;       // bilinear within a level
layout(set = 0, binding = 4) uniform Disk { vec4 points[32]; } disk;
layout(push_constant) uniform Push {
    vec2 size;          // level-0 size in pixels
    float tanHalfFovy;
    float mmPerUnit;
    vec4 falloff[3];    // rgb: k in exp(-k |q|^2), for 8, 16 and 32 samples
    float radiusMm;
    float depthSensitivity;   // per mm^2
    float normalSensitivity;
    int maxLevel;
    uint code;          // the compute path: the group's stencil code
} pc;
vec4 poissonSss(ivec2 p) {
    vec4 colorM = COUNTED(SITE(0, 0, FK_POINT), texelFetch(colorChain, p, 0));
    float d = COUNTED(SITE(0, 1, FK_POINT), texelFetch(depthChain, p, 0)).r;
    vec3 n = COUNTED(SITE(0, 2, FK_POINT), texelFetch(normalChain, p, 0)).xyz;
    vec2 uv = (vec2(p) + 0.5) / pc.size;
    // Pixels per mm times the radius, in this shader's own order of products
    // (mm_per_unit first, unlike view_scale.glsl): its images are hashed bit
    // for bit, and skin::screen_mirror rounds the same way.
    float rPx = pc.radiusMm / (pc.mmPerUnit * 2.0 * d * pc.tanHalfFovy) * pc.size.y * colorM.a;
    int count = rPx >= 16.0 ? 32 : (rPx >= 8.0 ? 16 : 8);
    vec3 falloff = pc.falloff[count == 32 ? 2 : (count == 16 ? 1 : 0)].rgb;
    float lod = clamp(floor(log2(max(rPx, 1.0) / 16.0)), 0.0, float(pc.maxLevel));
    vec3 acc = colorM.rgb;
    vec3 total = vec3(1.0);
    for (int i = 0; i < count; i++) {
        vec2 q = disk.points[i].xy;
        vec2 uvS = uv + vec2(q.x * rPx / pc.size.x, q.y * rPx / pc.size.y);
        vec4 c = COUNTED(SITE(0, 0, FK_BILINEAR), textureLod(sampler2D(colorChain, mipClamp), uvS, lod));
        float ds = COUNTED(SITE(0, 1, FK_BILINEAR), textureLod(sampler2D(depthChain, mipClamp), uvS, lod)).r;
        vec3 ns = COUNTED(SITE(0, 2, FK_BILINEAR), textureLod(sampler2D(normalChain, mipClamp), uvS, lod)).xyz;
        float dD = (ds - d) * pc.mmPerUnit;
        float wc = c.a * exp(-pc.depthSensitivity * dD * dD) * exp(-pc.normalSensitivity * (1.0 - clamp(dot(ns, n), 0.0, 1.0)));
        vec3 w = wc * exp(-falloff * (q.x * q.x + q.y * q.y));
        acc += c.rgb * w;
        total += w;
    }
    return vec4(acc / total, colorM.a);
}
#endif
