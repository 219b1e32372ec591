#ifndef DERMIS_LIGHTING_GLSL
#define DERMIS_LIGHTING_GLSL
// The shading model shared by the geometry pass and the ground-truth reference
// (reference_irradiance.comp): resources, shadow lookup, Lambert diffuse with
// normal mapping, transmittance, Kelemen/Szirmay-Kalos specular. One place, so
// the reference lights its surface samples exactly as the frame lights pixels.
// Every fetch names LOD 0 (the textures have one level), so the code does not
// depend on derivatives (the reference runs it over surface samples, not pixels).
#include "frame_uniforms.glsl"
#include "fetch_count.glsl"
#include "shader_constants.glsl"
#include "driver_workarounds.glsl"
layout(set = 0, binding = 1) uniform texture2D shadowMap;
layout(set = 0, binding = 2) uniform samplerShadow shadowCompare;  // LESS_OR_EQUAL, bilinear: 2x2 PCF
layout(set = 0, binding = 3) uniform sampler nearestClamp;
layout(set = 0, binding = 4) uniform texture2D beckmannTex;
layout(set = 0, binding = 5) uniform sampler linearClamp;
layout(set = 1, binding = 0) uniform texture2D albedoTex;
layout(set = 1, binding = 1) uniform texture2D normalTex;
layout(set = 1, binding = 2) uniform texture2D specTex;
layout(set = 1, binding = 4) uniform sampler materialSampler;
// Expression wrinkles (thesis ch. 8, src/scene/wrinkle_maps.rs): the
// partial-derivative wrinkle map (R, G) and two masks of four zones each.
layout(set = 1, binding = 5) uniform texture2D wrinkleTex;
layout(set = 1, binding = 6) uniform texture2D wrinkleMask0;
layout(set = 1, binding = 7) uniform texture2D wrinkleMask1;
// specTex holds the per-texel parameters (src/scene/texel_params.rs): R a factor
// of rho_s, G the Beckmann m where maps.x is 1, B a factor of the SSS strength.
layout(set = 1, binding = 3) uniform MaterialUniforms {
    vec4 baseColor;   // rgb linear factor
    vec4 params;      // x: Beckmann roughness m, y: rho_s, z: SSS strength, w: 1 if skin
    vec4 maps;        // x: 1 if specTex's G is a roughness map, y: 1 if it has wrinkle maps
} material;

// Thesis eq. 5.12 with the six-Gaussian weights (Listing 5.1); s in millimetres.
// frame.shadowParams.z scales the exponent: 1 for eq. 5.12 as published, 0.5 for
// the plane integral of the profile (src/skin/transmittance.rs says why).
vec3 transmittanceProfile(float s) {
    float s2 = s * s * frame.shadowParams.z;
    return SIX_GAUSSIAN_WEIGHT_0 * exp(-s2 / SIX_GAUSSIAN_VARIANCE_0) +
           SIX_GAUSSIAN_WEIGHT_1 * exp(-s2 / SIX_GAUSSIAN_VARIANCE_1) +
           SIX_GAUSSIAN_WEIGHT_2 * exp(-s2 / SIX_GAUSSIAN_VARIANCE_2) +
           SIX_GAUSSIAN_WEIGHT_3 * exp(-s2 / SIX_GAUSSIAN_VARIANCE_3) +
           SIX_GAUSSIAN_WEIGHT_4 * exp(-s2 / SIX_GAUSSIAN_VARIANCE_4) +
           SIX_GAUSSIAN_WEIGHT_5 * exp(-s2 / SIX_GAUSSIAN_VARIANCE_5);
}

vec3 shadowCoord(vec3 worldPos) {
    vec4 p = frame.lightViewProj * vec4(worldPos, 1.0);
    return vec3(p.xy * 0.5 + 0.5, p.z);
}


// 3x3 PCF over 2x2 filtered comparisons (PCF_RADIUS, PCF_TRIPS in src/shader_constants.rs).
float shadowPcf(vec3 worldPos, vec3 n) {
    vec3 c = shadowCoord(worldPos);
    float texel = frame.shadowParams.x;
    // Beyond the light frustum's far plane nothing recorded can be behind the
    // receiver: clamp so such points compare like points on the far plane.
    float ref = min(c.z - frame.shadowParams.y, 1.0);
    float sum = 0.0;
    for (int y = -PCF_RADIUS; y <= PCF_RADIUS; y++)
        for (int x = -PCF_RADIUS; x <= PCF_RADIUS; x++) {
            vec2 uv = c.xy + vec2(x, y) * texel;
            sum += COUNTED(SITE(0, 1, FK_COMPARE), textureLod(sampler2DShadow(shadowMap, shadowCompare), vec3(uv, ref), 0.0));
        }
    return sum / PCF_TAPS;
}

float fresnelSchlick(float vDotH, float f0) {
    float base = 1.0 - clamp(vDotH, 0.0, 1.0);
    float e = pow(base, 5.0);
    return e + f0 * (1.0 - e);
}

// Kelemen/Szirmay-Kalos with the precomputed Beckmann texture (seed 004 listing).
float kelemenSzirmayKalos(vec3 N, vec3 L, vec3 V, float m, float rhoS) {
    float nDotL = dot(N, L);
    if (nDotL <= 0.0) return 0.0;
    vec3 h = L + V;
    vec3 H = normalize(h);
    float nDotH = dot(N, H);
    float PH = pow(2.0 * COUNTED(SITE(0, 4, FK_BILINEAR), textureLod(sampler2D(beckmannTex, linearClamp), vec2(nDotH, m), 0.0)).r, 10.0);
    float F = fresnelSchlick(dot(H, V), 0.028);
    float frSpec = max(PH * F / dot(h, h), 0.0);
    return nDotL * rhoS * frSpec;
}


// Listing 8.1's sum: the wrinkle map's partial derivatives (decoded -1 + 2 c)
// times each zone's mask times its weight, zone by zone. `zones` holds the
// draw's eight zone weights (Table 8.1 summed over the expressions and
// clamped: src/skin/wrinkles.rs); all 0, or a material without wrinkle maps,
// fetches nothing (the thesis' far characters, "progressively disabled").
vec2 wrinkleSlope(vec2 uv, vec4 zones[2]) {
    // maps.y is a uniform value: NOT_UNIFORM_ZERO keeps lavapipe from
    // compiling (and leaking) a copy of each shader per bind.
    if (material.maps.y + NOT_UNIFORM_ZERO < 0.5 || dot(zones[0] + zones[1], vec4(1.0)) <= 0.0)
        return vec2(0.0);
    vec2 wrinkles = -1.0 + 2.0 * COUNTED(SITE(1, 5, FK_BILINEAR), textureLod(sampler2D(wrinkleTex, materialSampler), uv, 0.0)).rg;
    vec4 mask1 = COUNTED(SITE(1, 6, FK_BILINEAR), textureLod(sampler2D(wrinkleMask0, materialSampler), uv, 0.0)) * zones[0];
    vec4 mask2 = COUNTED(SITE(1, 7, FK_BILINEAR), textureLod(sampler2D(wrinkleMask1, materialSampler), uv, 0.0)) * zones[1];
    vec2 d = vec2(0.0);
    d += mask1.r * wrinkles;
    d += mask1.g * wrinkles;
    d += mask1.b * wrinkles;
    d += mask1.a * wrinkles;
    d += mask2.r * wrinkles;
    d += mask2.g * wrinkles;
    d += mask2.b * wrinkles;
    d += mask2.a * wrinkles;
    return d;
}

// The tangent-space normal map applied to the vertex normal, with the
// draw's wrinkles (`zones`, see wrinkleSlope) added to it as partial
// derivatives (8.2: the base normal's (x / z, y / z) plus the wrinkles',
// renormalised). No wrinkle, no change: the normal map's normal as it is.
vec3 shadingNormal(vec3 Nv, vec4 tangent, vec2 uv, vec4 zones[2]) {
    vec3 T = tangent.xyz - Nv * dot(Nv, tangent.xyz);
    if (dot(T, T) <= 1e-12) return Nv;
    T = normalize(T);
    vec3 B = cross(Nv, T) * tangent.w;
    vec3 tn = COUNTED(SITE(1, 1, FK_BILINEAR), textureLod(sampler2D(normalTex, materialSampler), uv, 0.0)).xyz * 2.0 - 1.0;
    vec2 wrinkles = wrinkleSlope(uv, zones);
    if (wrinkles != vec2(0.0))
        tn = vec3(tn.xy / max(tn.z, 1e-3) + wrinkles, 1.0);
    return normalize(mat3(T, B, Nv) * tn);
}

vec3 albedoAt(vec2 uv) {
    return COUNTED(SITE(1, 0, FK_BILINEAR), textureLod(sampler2D(albedoTex, materialSampler), uv, 0.0)).rgb * material.baseColor.rgb;
}

// The albedo the light is scattered with: the albedo itself (pre-scatter
// texturing), or 1 when the composite applies it after the SSS (post-scatter;
// frame.shading.x, src/render/settings.rs Texturing).
// (A uniform flag: NOT_UNIFORM_ZERO keeps lavapipe from compiling, and leaking,
// a copy of each shader that calls this per bind; driver_workarounds.glsl.)
vec3 scatteredAlbedo(vec3 albedo) {
    return frame.shading.x + NOT_UNIFORM_ZERO > 0.5 ? vec3(1.0) : albedo;
}

// Diffuse radiance before scattering: albedo x (key light x N.L x shadow + ambient).
vec3 diffuseLight(vec3 albedo, vec3 N, float shadow) {
    vec3 L = normalize(frame.lightDir.xyz);
    return albedo * (frame.lightColor.rgb * max(dot(N, L), 0.0) * shadow + frame.ambient.rgb);
}
#endif
