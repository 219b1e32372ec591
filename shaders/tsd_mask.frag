#version 450
#extension GL_GOOGLE_include_directive : require
// Texture-space diffusion, the mask pass's discarding draws: Gosselin's backface
// z pre-pass (writes depth 1 where N.V + 0.3 < 0) and the thesis' culled map as a
// stencil mask (writes the bit where N.V >= cos 105). Late tests: what is
// discarded writes nothing. (No fetch, so no counter: see fetch_count.glsl.)
#include "tsd_character.glsl"
layout(location = 0) in vec3 vWorldPos;
layout(location = 1) in vec3 vNormal;
layout(location = 2) in vec4 vTangent;
layout(location = 3) in vec2 vUv;
layout(location = 4) in float vEyeDot;
void main() {
    bool above = vEyeDot >= pc.threshold;
    if (above != (pc.keepAbove > 0.5)) discard;
}
