#version 450
#extension GL_GOOGLE_include_directive : require
// Texture-space diffusion: a Gaussian's pass along u (into the temporary map).
#include "tsd_blur.glsl"
layout(location = 0) in vec2 vUv;   // fullscreen.vert's (the texel comes from gl_FragCoord)
layout(location = 0) out vec4 outTemp;
void main() {
    outTemp = tsdBlur();
}
