#version 450
#extension GL_GOOGLE_include_directive : require
#include "fetch_count.glsl"
// Ceiling probe: N fetches per fragment from one texture (bilinear or point,
// chosen by the bound sampler) at sub-texel offsets, like an SSS tap.
layout(set = 0, binding = 0) uniform texture2D srcTex;
layout(set = 0, binding = 1) uniform sampler srcSampler;
layout(push_constant) uniform Push { vec2 texel; int taps; int pad; } pc;
layout(location = 0) in vec2 vUv;
layout(location = 0) out vec4 outColor;
void main() {
    COUNT_INVOCATION();
    vec4 acc = vec4(0.0);
    for (int i = 0; i < pc.taps; i++) {
        acc += COUNTED(SITE(0, 0, FK_BILINEAR), texture(sampler2D(srcTex, srcSampler), vUv + vec2(float(i - pc.taps / 2) * 0.37, 0.25) * pc.texel));
    }
    outColor = acc * (1.0 / float(max(pc.taps, 1)));
}
