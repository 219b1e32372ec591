#version 450
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_GOOGLE_include_directive : require
#include "fetch_count.glsl"
// Adds the specular target to the (scattered) diffuse one, linear HDR.
layout(set = 0, binding = 0) uniform texture2D diffuseTex;
layout(set = 0, binding = 1) uniform texture2D specularTex;
layout(location = 0) in vec2 vUv;
layout(location = 0) out vec4 outColor;
void main() {
    COUNT_INVOCATION();
    vec3 diffuse = COUNTED(SITE(0, 0, FK_POINT), texelFetch(diffuseTex, ivec2(gl_FragCoord.xy), 0)).rgb;
    vec3 specular = COUNTED(SITE(0, 1, FK_POINT), texelFetch(specularTex, ivec2(gl_FragCoord.xy), 0)).rgb;
    outColor = vec4(diffuse + specular, 1.0);
}
