// The geometry pass body, shared by geometry.frag and geometry_normals.frag.
#include "frame_uniforms.glsl"
layout(set = 0, binding = 1) uniform texture2D shadowMap;
layout(set = 0, binding = 2) uniform samplerShadow shadowCompare;  // LESS_OR_EQUAL, bilinear: 2x2 PCF
layout(set = 0, binding = 3) uniform sampler nearestClamp;
layout(set = 0, binding = 4) uniform texture2D beckmannTex;
layout(set = 0, binding = 5) uniform sampler linearClamp;
layout(set = 1, binding = 0) uniform texture2D albedoTex;
layout(set = 1, binding = 1) uniform texture2D normalTex;
layout(set = 1, binding = 2) uniform texture2D specTex;
layout(set = 1, binding = 4) uniform sampler materialSampler;
layout(set = 1, binding = 3) uniform MaterialUniforms {
    vec4 baseColor;   // rgb linear factor
    vec4 params;      // x: Beckmann roughness m, y: rho_s, z: SSS strength, w: 1 if skin
} material;

layout(location = 0) in vec3 vWorldPos;
layout(location = 1) in vec3 vNormal;
layout(location = 2) in vec4 vTangent;
layout(location = 3) in vec2 vUv;
layout(location = 4) in float vViewDepth;

layout(location = 0) out vec4 outDiffuse;
layout(location = 1) out vec4 outSpecular;
layout(location = 2) out float outDepth;
#ifdef WRITE_NORMALS
// View-space shading normal, for methods that weigh samples by normal difference.
layout(location = 3) out vec4 outNormal;
#endif

// Thesis eq. 5.12 with the six-Gaussian weights (Listing 5.1); s in millimetres.
vec3 transmittanceProfile(float s) {
    float s2 = s * s;
    return vec3(0.233, 0.455, 0.649) * exp(-s2 / 0.0064) +
           vec3(0.1, 0.336, 0.344) * exp(-s2 / 0.0484) +
           vec3(0.118, 0.198, 0.0) * exp(-s2 / 0.187) +
           vec3(0.113, 0.007, 0.007) * exp(-s2 / 0.567) +
           vec3(0.358, 0.004, 0.0) * exp(-s2 / 1.99) +
           vec3(0.078, 0.0, 0.0) * exp(-s2 / 7.41);
}

vec3 shadowCoord(vec3 worldPos) {
    vec4 p = frame.lightViewProj * vec4(worldPos, 1.0);
    return vec3(p.xy * 0.5 + 0.5, p.z);
}

// 3x3 PCF over 2x2 hardware-filtered comparisons.
float shadowPcf(vec3 worldPos, vec3 n) {
    vec3 c = shadowCoord(worldPos);
    float texel = frame.shadowParams.x;
    // Beyond the light frustum's far plane nothing recorded can be behind the
    // receiver: clamp so such points compare like points on the far plane.
    float ref = min(c.z - frame.shadowParams.y, 1.0);
    float sum = 0.0;
    for (int y = -1; y <= 1; y++)
        for (int x = -1; x <= 1; x++)
            sum += texture(sampler2DShadow(shadowMap, shadowCompare), vec3(c.xy + vec2(x, y) * texel, ref));
    return sum / 9.0;
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
    float PH = pow(2.0 * texture(sampler2D(beckmannTex, linearClamp), vec2(nDotH, m)).r, 10.0);
    float F = fresnelSchlick(dot(H, V), 0.028);
    float frSpec = max(PH * F / dot(h, h), 0.0);
    return nDotL * rhoS * frSpec;
}

void main() {
    vec3 Nv = normalize(vNormal);
    vec3 T = vTangent.xyz - Nv * dot(Nv, vTangent.xyz);
    T = dot(T, T) > 1e-12 ? normalize(T) : vec3(0.0);
    vec3 B = cross(Nv, T) * vTangent.w;
    vec3 tn = texture(sampler2D(normalTex, materialSampler), vUv).xyz * 2.0 - 1.0;
    vec3 N = normalize(mat3(T, B, Nv) * tn);
    if (dot(T, T) == 0.0) N = Nv;

    vec3 albedo = texture(sampler2D(albedoTex, materialSampler), vUv).rgb * material.baseColor.rgb;
    vec3 L = normalize(frame.lightDir.xyz);
    vec3 V = normalize(frame.cameraPos.xyz - vWorldPos);
    float shadow = shadowPcf(vWorldPos, Nv);
    vec3 light = frame.lightColor.rgb;
    bool skin = material.params.w > 0.5;

    vec3 diffuse = albedo * (light * max(dot(N, L), 0.0) * shadow + frame.ambient.rgb);

    if (skin && frame.params.w > 0.5) {
        // Listing 5.1: shrink along the vertex normal, read the light-side depth,
        // distance in millimetres, back irradiance from the reversed vertex normal.
        vec3 c = shadowCoord(vWorldPos - frame.params.z * Nv);
        float d1 = texture(sampler2D(shadowMap, nearestClamp), c.xy).r;
        float sMm = abs(c.z - d1) * frame.params.y * frame.params.x;
        float E = max(0.3 + dot(-Nv, L), 0.0);
        diffuse += transmittanceProfile(sMm) * light * albedo * E;
    }

    float specMask = texture(sampler2D(specTex, materialSampler), vUv).r;
    float spec = kelemenSzirmayKalos(N, L, V, material.params.x, material.params.y) * specMask;

    outDiffuse = vec4(diffuse, skin ? material.params.z : 0.0);
    outSpecular = vec4(light * spec * shadow, 1.0);
    outDepth = vViewDepth;
#ifdef WRITE_NORMALS
    outNormal = vec4(normalize(mat3(frame.view) * N), 0.0);
#endif
}
