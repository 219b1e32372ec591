#version 450
#extension GL_GOOGLE_include_directive : require
// Texture-space diffusion: a Gaussian's pass along v, into the chain's next map
// and, through MRT, into the character's map: G_i / a_i blended with the
// constant w'_i of eq. 4.8 (eq. 4.9), alpha 1 where any written texel is near.
#include "tsd_blur.glsl"
layout(location = 0) in vec2 vUv;   // fullscreen.vert's (the texel comes from gl_FragCoord)
layout(location = 0) out vec4 outNext;
layout(location = 1) out vec4 outMap;
void main() {
    vec4 g = tsdBlur();
    outNext = g;
    outMap = g.a > 0.0 ? vec4(g.rgb / g.a, 1.0) : vec4(0.0);
}
