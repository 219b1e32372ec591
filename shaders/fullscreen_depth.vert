#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
// The full-screen triangle at a chosen depth: with depth test GREATER, only
// pixels whose surface is nearer than that depth are shaded (thesis 4.2.1).
#include "screen_common.glsl"
layout(location = 0) out vec2 vUv;
void main() {
    vec2 p = vec2((gl_VertexIndex << 1) & 2, gl_VertexIndex & 2);
    vUv = p;
    gl_Position = vec4(p * 2.0 - 1.0, pc.quadDepth, 1.0);
}
