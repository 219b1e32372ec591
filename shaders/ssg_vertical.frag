#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
// ssg vertical pass: RT2 -> RT1 (unblended) and RTF (blended with w'_i, eq. 4.9) via MRT.
#include "screen_common.glsl"
#include "ssg_blur.glsl"
layout(location = 0) in vec2 vUv;
layout(location = 0) out vec4 outRt1;
layout(location = 1) out vec4 outFinal;
void main() {
    vec4 c = ssgBlur();
    outRt1 = c;
    outFinal = c;
}
