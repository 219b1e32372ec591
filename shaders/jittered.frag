#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
// SS Jittered on the fragment path (the arithmetic: jittered_body.glsl),
// stencil-tested on the skin bit.
layout(early_fragment_tests) in;
#include "screen_common.glsl"
#include "jittered_body.glsl"
layout(location = 0) in vec2 vUv;
layout(location = 0) out vec4 outColor;

void main() {
    COUNT_INVOCATION();
    outColor = jitteredSss(ivec2(gl_FragCoord.xy));
}
