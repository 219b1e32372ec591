#ifndef DERMIS_GEOMETRY_BODY_GLSL
#define DERMIS_GEOMETRY_BODY_GLSL
// The geometry pass body, shared by geometry.frag and geometry_normals.frag.
#include "lighting.glsl"
#include "driver_workarounds.glsl"

layout(location = 0) in vec3 vWorldPos;
layout(location = 1) in vec3 vNormal;
layout(location = 2) in vec4 vTangent;
layout(location = 3) in vec2 vUv;
layout(location = 4) in float vViewDepth;
// The character's wrinkle zone weights (geometry_instanced.vert).
layout(location = 5) flat in vec4 vZones0;
layout(location = 6) flat in vec4 vZones1;

layout(location = 0) out vec4 outDiffuse;
layout(location = 1) out vec4 outSpecular;
layout(location = 2) out float outDepth;
#ifdef WRITE_NORMALS
// View-space shading normal, for methods that weigh samples by normal difference.
layout(location = 3) out vec4 outNormal;
#endif
#ifdef WRITE_ALBEDO
// Post-scatter texturing: the albedo, which the composite applies after the SSS
// (WRITE_ALBEDO is its attachment's location).
layout(location = WRITE_ALBEDO) out vec4 outAlbedo;
#endif

void main() {
    COUNT_INVOCATION();
    vec3 Nv = normalize(vNormal);
    vec3 N = shadingNormal(Nv, vTangent, vUv, vec4[2](vZones0, vZones1));
    vec3 albedo = albedoAt(vUv);
    vec3 L = normalize(frame.lightDir.xyz);
    vec3 V = normalize(frame.cameraPos.xyz - vWorldPos);
    float shadow = shadowPcf(vWorldPos, Nv);
    vec3 light = frame.lightColor.rgb;
    // Both flags are uniform values: NOT_UNIFORM_ZERO keeps lavapipe from
    // compiling (and leaking) a copy of this shader per material bind.
    bool skin = material.params.w + NOT_UNIFORM_ZERO > 0.5;
    bool transmit = frame.params.w + NOT_UNIFORM_ZERO > 0.5;

    // Post-scatter texturing leaves the albedo to the composite.
    vec3 scattered = scatteredAlbedo(albedo);
    vec3 diffuse = diffuseLight(scattered, N, shadow);

    if (skin && transmit) {
        // Listing 5.1: shrink along the vertex normal, read the light-side depth,
        // distance in millimetres, back irradiance from the reversed vertex normal.
        vec3 c = shadowCoord(vWorldPos - frame.params.z * Nv);
        float d1 = COUNTED(SITE(0, 1, FK_POINT), texture(sampler2D(shadowMap, nearestClamp), c.xy)).r;
        float sMm = abs(c.z - d1) * frame.params.y * frame.params.x;
        float E = max(0.3 + dot(-Nv, L), 0.0);
        diffuse += transmittanceProfile(sMm) * light * scattered * E;
    }

    // The per-texel parameters, one fetch (lighting.glsl's specTex).
    vec3 texel = COUNTED(SITE(1, 2, FK_BILINEAR), texture(sampler2D(specTex, materialSampler), vUv)).rgb;
    float m = material.maps.x + NOT_UNIFORM_ZERO > 0.5 ? texel.g : material.params.x;
    float spec = kelemenSzirmayKalos(N, L, V, m, material.params.y) * texel.r;

    outDiffuse = vec4(diffuse, skin ? material.params.z * texel.b : 0.0);
    outSpecular = vec4(light * spec * shadow, 1.0);
    outDepth = vViewDepth;
#ifdef WRITE_NORMALS
    outNormal = vec4(normalize(mat3(frame.view) * N), 0.0);
#endif
#ifdef WRITE_ALBEDO
    outAlbedo = vec4(albedo, 1.0);
#endif
}
#endif
