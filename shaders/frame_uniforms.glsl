#ifndef DERMIS_FRAME_UNIFORMS_GLSL
#define DERMIS_FRAME_UNIFORMS_GLSL
// Per-frame constants shared by the shadow and geometry passes (std140).
layout(set = 0, binding = 0) uniform FrameUniforms {
    mat4 viewProj;
    mat4 view;
    mat4 lightViewProj;
    vec4 cameraPos;     // xyz
    vec4 lightDir;      // xyz: unit direction towards the key light
    vec4 lightColor;    // rgb: colour x intensity
    vec4 ambient;       // rgb: constant ambient irradiance
    vec4 params;        // x: mm per unit, y: shadow depth range (units), z: normal shrink (units), w: transmittance on
    vec4 shadowParams;  // x: 1 / shadow map size, y: receiver depth bias (shadow depth units), z: T(s) exponent scale
    vec4 shading;       // x: 1 for post-scatter texturing (the albedo applied after the SSS)
} frame;
#endif
