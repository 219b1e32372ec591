#version 450
#extension GL_GOOGLE_include_directive : require
// Texture-space diffusion, per character: the irradiance map (the diffuse light
// of lighting.glsl, shadow map and transmittance included, as the geometry pass
// shades a pixel) with coverage in alpha, and d'Eon's stretch maps (texels per
// millimetre along the map's x and y, from the world position's derivatives).
// Texels the depth/stencil masks removed never run (early tests forced); with
// the thesis' alpha test, a culled texel writes alpha 0 (Listing 3.2).
layout(early_fragment_tests) in;
#include "lighting.glsl"
#include "tsd_character.glsl"
layout(location = 0) in vec3 vWorldPos;
layout(location = 1) in vec3 vNormal;
layout(location = 2) in vec4 vTangent;
layout(location = 3) in vec2 vUv;
layout(location = 4) in float vEyeDot;
layout(location = 0) out vec4 outIrradiance;
layout(location = 1) out float outStretchU;
layout(location = 2) out float outStretchV;
void main() {
    COUNT_INVOCATION();
    // Derivatives first, in uniform control flow.
    float mm = frame.params.x;
    outStretchU = 1.0 / max(length(dFdx(vWorldPos)) * mm, 1e-4);
    outStretchV = 1.0 / max(length(dFdy(vWorldPos)) * mm, 1e-4);
    if (vEyeDot < ch.params.z) {
        outIrradiance = vec4(0.0);
        return;
    }
    vec3 Nv = normalize(vNormal);
    vec3 N = shadingNormal(Nv, vTangent, vUv, ch.zones);
    vec3 albedo = scatteredAlbedo(albedoAt(vUv));  // 1 with post-scatter texturing
    vec3 L = normalize(frame.lightDir.xyz);
    float shadow = shadowPcf(vWorldPos, Nv);
    vec3 irradiance = diffuseLight(albedo, N, shadow);
    if (frame.params.w + NOT_UNIFORM_ZERO > 0.5) {
        // Transmittance (thesis Listing 5.1), as the geometry pass adds it: part
        // of the light the maps blur.
        vec3 c = shadowCoord(vWorldPos - frame.params.z * Nv);
        float d1 = COUNTED(SITE(0, 1, FK_POINT), texture(sampler2D(shadowMap, nearestClamp), c.xy)).r;
        float sMm = abs(c.z - d1) * frame.params.y * frame.params.x;
        float E = max(0.3 + dot(-Nv, L), 0.0);
        irradiance += transmittanceProfile(sMm) * frame.lightColor.rgb * albedo * E;
    }
    outIrradiance = vec4(irradiance, 1.0);
}
