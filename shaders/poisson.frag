#version 450
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_GOOGLE_include_directive : require
// Poisson-disk SSS on the fragment path (the arithmetic: poisson_body.glsl),
// stencil-tested on the skin bit.
layout(early_fragment_tests) in;
#include "poisson_body.glsl"
layout(location = 0) in vec2 vUv;
layout(location = 0) out vec4 outColor;

void main() {
    COUNT_INVOCATION();
    outColor = poissonSss(ivec2(gl_FragCoord.xy));
}
