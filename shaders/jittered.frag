#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
// SS Jittered: Hable et al.'s 13-tap 2D kernel in screen space (1 direct, 6 mid,
// 6 wide red samples), rings rotated per pixel, positions scaled by the stretch factors.
layout(early_fragment_tests) in;
#include "screen_common.glsl"
layout(location = 0) in vec2 vUv;
layout(location = 0) out vec4 outColor;

// Integer hash -> rotation in [0, pi/3): the rings repeat every 60 degrees.
float jitterAngle(uvec2 p) {
    uint h = p.x * 1973u + p.y * 9277u;
    h = (h ^ (h >> 13u)) * 0x5bd1e995u;
    h ^= h >> 15u;
    return float(h & 0xffffu) / 65536.0 * (3.14159265358979 / 3.0);
}

void main() {
    COUNT_INVOCATION();
    ivec2 p = ivec2(gl_FragCoord.xy);
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
        vec3 c = COUNTED(SITE(0, 0, FK_BILINEAR), texture(sampler2D(colorTex, linearClamp), uv + vec2(cos(a), sin(a)) * pc.wide.y * mmToUv)).rgb;
        acc += (pc.mid.rgb / 6.0) * c;
        float b = a + PI / 6.0;
        vec3 cw = COUNTED(SITE(0, 0, FK_BILINEAR), texture(sampler2D(colorTex, linearClamp), uv + vec2(cos(b), sin(b)) * pc.wide.z * mmToUv)).rgb;
        acc.r += (pc.wide.x / 6.0) * cw.r;
    }
    outColor = vec4(acc, colorM.a);
}
