#version 450
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_GOOGLE_include_directive : require
#include "fetch_count.glsl"
// A frame of several methods: copies one group's output into the diffuse
// target the composite reads, on its pixels only (the pass is stencil-tested
// on the group's code and drawn in its SSS region).
layout(set = 0, binding = 0) uniform texture2D groupTex;
layout(location = 0) in vec2 vUv;
layout(location = 0) out vec4 outColor;
void main() {
    COUNT_INVOCATION();
    outColor = COUNTED(SITE(0, 0, FK_POINT), texelFetch(groupTex, ivec2(gl_FragCoord.xy), 0));
}
