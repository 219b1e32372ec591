#version 450
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_GOOGLE_include_directive : require
#include "fetch_count.glsl"
// Hable's filmic curve; the sRGB attachment does the encode.
layout(set = 0, binding = 0) uniform texture2D hdrTex;
layout(push_constant) uniform Push { float exposure; float whitePoint; } pc;
layout(location = 0) in vec2 vUv;
layout(location = 0) out vec4 outColor;
vec3 hable(vec3 x) {
    const float A = 0.15, B = 0.50, C = 0.10, D = 0.20, E = 0.02, F = 0.30;
    return ((x * (A * x + C * B) + D * E) / (x * (A * x + B) + D * F)) - E / F;
}
void main() {
    COUNT_INVOCATION();
    vec3 c = COUNTED(SITE(0, 0, FK_POINT), texelFetch(hdrTex, ivec2(gl_FragCoord.xy), 0)).rgb * pc.exposure;
    vec3 w = hable(vec3(pc.whitePoint));
    outColor = vec4(clamp(hable(c) / w, 0.0, 1.0), 1.0);
}
