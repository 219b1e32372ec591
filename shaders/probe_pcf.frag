#version 450
#extension GL_GOOGLE_include_directive : require
#include "fetch_count.glsl"
// Ceiling probe (bench::ceilings): depth-compare (2x2 PCF) fetches of a D32
// depth image, as the geometry pass's shadow taps: N per fragment at
// sub-texel offsets, like probe_fetch.frag's.
layout(set = 0, binding = 0) uniform texture2D srcTex;
layout(set = 0, binding = 1) uniform samplerShadow srcSampler;
layout(push_constant) uniform Push { vec2 texel; int taps; int pad; } pc;
layout(location = 0) in vec2 vUv;
layout(location = 0) out vec4 outColor;
void main() {
    COUNT_INVOCATION();
    float acc = 0.0;
    for (int i = 0; i < pc.taps; i++) {
        vec2 uv = vUv + vec2(float(i - pc.taps / 2) * 0.37, 0.25) * pc.texel;
        acc += COUNTED(SITE(0, 0, FK_COMPARE), texture(sampler2DShadow(srcTex, srcSampler), vec3(uv, 0.5)));
    }
    outColor = vec4(acc * (1.0 / float(max(pc.taps, 1))));
}
