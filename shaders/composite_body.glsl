#ifndef DERMIS_COMPOSITE_BODY_GLSL
#define DERMIS_COMPOSITE_BODY_GLSL
#include "fetch_count.glsl"
// Adds the specular target to the (scattered) diffuse one, linear HDR; with
// READ_ALBEDO (post-scatter texturing) the diffuse is light alone and the
// pixel's albedo multiplies it first.
layout(set = 0, binding = 0) uniform texture2D diffuseTex;
layout(set = 0, binding = 1) uniform texture2D specularTex;
#ifdef READ_ALBEDO
layout(set = 0, binding = 2) uniform texture2D albedoTex;
#endif
layout(location = 0) in vec2 vUv;
layout(location = 0) out vec4 outColor;
void main() {
    COUNT_INVOCATION();
    vec3 diffuse = COUNTED(SITE(0, 0, FK_POINT), texelFetch(diffuseTex, ivec2(gl_FragCoord.xy), 0)).rgb;
    vec3 specular = COUNTED(SITE(0, 1, FK_POINT), texelFetch(specularTex, ivec2(gl_FragCoord.xy), 0)).rgb;
#ifdef READ_ALBEDO
    diffuse *= COUNTED(SITE(0, 2, FK_POINT), texelFetch(albedoTex, ivec2(gl_FragCoord.xy), 0)).rgb;
#endif
    outColor = vec4(diffuse + specular, 1.0);
}
#endif
