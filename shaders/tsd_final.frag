#version 450
#extension GL_GOOGLE_include_directive : require
// Texture-space diffusion, the final mesh pass (with geometry.vert, so it lands
// on exactly the pixels the geometry pass wrote; depth tested against them):
// the character's map, the sum of the six blurred Gaussians with the fit's RGB
// weights, looked up at the pixel's atlas UV within the depth-sized square and
// divided by its coverage. Specular is the frame's own target. The material's
// per-texel SSS strength (src/scene/texel_params.rs) times the character's
// mixes it with the geometry pass's unblurred light (the pipeline blends by
// alpha): a texel of strength 0 (a beard) keeps its own light, as the
// screen-space methods' kernels shrink to nothing there (eq. 4.3-4.4), and 1
// takes the map whole. Between, a mix stands in for a narrower kernel.
layout(early_fragment_tests) in;
#include "fetch_count.glsl"
#include "shader_constants.glsl"
layout(set = 1, binding = 0) uniform texture2D mapTex;
layout(set = 1, binding = 1) uniform sampler linearClamp;
layout(set = 1, binding = 2) uniform CharacterUniforms {
    mat4 model;
    vec4 planes[6];
    vec4 params;      // x: s (eq. 3.1), y: SSS strength
    vec4 mapInfo;     // x: 1 / T_max, y: largest tap coordinate (see tsd_blur.glsl)
} ch;
layout(set = 1, binding = 3) uniform AtlasUniforms { vec4 islands[TSD_MAX_ISLANDS]; } atlas;
// The skin material's per-texel parameters (lighting.glsl's specTex; B: strength).
layout(set = 2, binding = 0) uniform texture2D specTex;
layout(set = 2, binding = 1) uniform sampler materialSampler;
// geometry.vert's outputs (all declared: an unread one is a validation warning).
layout(location = 0) in vec3 vWorldPos;
layout(location = 1) in vec3 vNormal;
layout(location = 2) in vec4 vTangent;   // w: handedness x (1 + atlas island), one value per triangle
layout(location = 3) in vec2 vUv;
layout(location = 4) in float vViewDepth;
layout(location = 0) out vec4 outDiffuse;
void main() {
    COUNT_INVOCATION();
    vec4 t = atlas.islands[int(abs(vTangent.w) + 0.5) - 1];
    vec2 uv = clamp((vUv * t.x + t.yz) * ch.params.x, vec2(0.5 * ch.mapInfo.x), vec2(ch.mapInfo.y));
    vec4 m = COUNTED(SITE(1, 0, FK_BILINEAR), texture(sampler2D(mapTex, linearClamp), uv));
    if (m.a <= 1e-3) {
        discard;   // nothing of the map near: the geometry pass's diffuse stays
    }
    float strength = ch.params.y * COUNTED(SITE(2, 0, FK_BILINEAR), texture(sampler2D(specTex, materialSampler), vUv)).b;
    outDiffuse = vec4(m.rgb / m.a, strength);
}
