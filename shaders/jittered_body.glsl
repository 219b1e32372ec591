#ifndef DERMIS_JITTERED_BODY_GLSL
#define DERMIS_JITTERED_BODY_GLSL
// SS Jittered's arithmetic for one pixel, shared by the fragment path
// (jittered.frag) and the compute path (jittered_tiles.comp): Hable et al.'s
// 13-tap 2D kernel in screen space (1 direct, 6 mid, 6 wide red samples),
// rings rotated per pixel, positions scaled by the stretch factors.
// Needs screen_common.glsl. Taps take level 0 explicitly (the images have
// one level): a compute shader has no implicit derivatives.

// Integer hash -> rotation in [0, pi/3): the rings repeat every 60 degrees.
float jitterAngle(uvec2 p) {
    uint h = p.x * 1973u + p.y * 9277u;
    h = (h ^ (h >> 13u)) * 0x5bd1e995u;
    h ^= h >> 15u;
    return float(h & 0xffffu) / 65536.0 * (3.14159265358979 / 3.0);
}

vec4 jitteredSss(ivec2 p) {
    vec4 colorM = COUNTED(SITE(0, 0, FK_POINT), texelFetch(colorTex, p, 0));
    float depth = COUNTED(SITE(0, 1, FK_POINT), texelFetch(depthTex, p, 0)).r;
    vec2 s = vec2(stretch(p, ivec2(1, 0), depth, colorM.a), stretch(p, ivec2(0, 1), depth, colorM.a));
    vec2 mmToUv = s / 3.0 * pc.texel;
    vec2 uv = (vec2(p) + 0.5) * pc.texel;
    float theta = jitterAngle(uvec2(p));
    const float PI = 3.14159265358979;
    vec3 acc = pc.center.rgb * colorM.rgb;
    for (int k = 0; k < 6; k++) {
        float a = theta + float(k) * (PI / 3.0);
        vec3 c = COUNTED(SITE(0, 0, FK_BILINEAR), textureLod(sampler2D(colorTex, linearClamp), uv + vec2(cos(a), sin(a)) * pc.wide.y * mmToUv, 0.0)).rgb;
        acc += (pc.mid.rgb / 6.0) * c;
        float b = a + PI / 6.0;
        vec3 cw = COUNTED(SITE(0, 0, FK_BILINEAR), textureLod(sampler2D(colorTex, linearClamp), uv + vec2(cos(b), sin(b)) * pc.wide.z * mmToUv, 0.0)).rgb;
        acc.r += (pc.wide.x / 6.0) * cw.r;
    }
    return vec4(acc, colorM.a);
}
#endif
