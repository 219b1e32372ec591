#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
// ssg horizontal pass: RT1 (widest Gaussian so far) -> RT2.
#include "screen_common.glsl"
#include "ssg_blur.glsl"
layout(location = 0) in vec2 vUv;
layout(location = 0) out vec4 outRt2;
void main() { outRt2 = ssgBlur(); }
