#version 450
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_GOOGLE_include_directive : require
#include "fetch_count.glsl"
#include "shader_constants.glsl"
#include "view_scale.glsl"
// Separable SSS, one direction per pass (thesis ch. 6 and its HLSL listing).
// Stencil-tested on the skin bit: early tests are forced so masked pixels never
// run this shader.
layout(early_fragment_tests) in;

layout(set = 0, binding = 0) uniform texture2D colorTex;   // RGBA16F, alpha = SSS strength
layout(set = 0, binding = 1) uniform texture2D depthTex;   // linear view depth, scene units
layout(set = 0, binding = 3) uniform sampler linearClamp;
layout(set = 0, binding = 2) uniform KernelUniforms {
    vec4 samples[SEPARABLE_MAX_SAMPLES];   // rgb weight, w: offset in millimetres; [0] is the centre
} kernel;
layout(push_constant) uniform Push {
    vec2 dir;           // (1,0) horizontal, (0,1) vertical
    float aspect;       // width / height
    float tanHalfFovy;
    float mmPerUnit;
    float followTolMm;  // depth difference (mm) at which a sample is fully replaced
    int nSamples;
    int followSurface;
} pc;

layout(location = 0) in vec2 vUv;
layout(location = 0) out vec4 outColor;

void main() {
    COUNT_INVOCATION();
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec4 colorM = COUNTED(SITE(0, 0, FK_POINT), texelFetch(colorTex, p, 0));
    float depthM = COUNTED(SITE(0, 1, FK_POINT), texelFetch(depthTex, p, 0)).r;
    vec2 uv = (vec2(p) + 0.5) / vec2(textureSize(sampler2D(colorTex, linearClamp), 0));

    // Screen height in scene units at this depth; one millimetre in uv, the same
    // on-screen length in both directions.
    float screenH = SCREEN_HEIGHT_UNITS(depthM, pc.tanHalfFovy);
    vec2 stepPerMm = pc.dir / (pc.mmPerUnit * screenH);
    stepPerMm.x /= pc.aspect;
    vec2 stepUv = stepPerMm * colorM.a;

    vec3 acc = colorM.rgb * kernel.samples[0].rgb;
    for (int i = 1; i < pc.nSamples; i++) {
        vec4 k = kernel.samples[i];
        vec2 o = uv + k.w * stepUv;
        vec3 c = COUNTED(SITE(0, 0, FK_BILINEAR), texture(sampler2D(colorTex, linearClamp), o)).rgb;
        if (pc.followSurface != 0) {
            // Follow the surface: a sample across a depth step larger than the
            // kernel is replaced by the centre colour.
            float d = COUNTED(SITE(0, 1, FK_BILINEAR), texture(sampler2D(depthTex, linearClamp), o)).r;
            float s = clamp(abs(depthM - d) * pc.mmPerUnit / pc.followTolMm, 0.0, 1.0);
            c = c + (colorM.rgb - c) * s;
        }
        acc += k.rgb * c;
    }
    outColor = vec4(acc, colorM.a);
}
