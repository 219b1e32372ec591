#version 450
#extension GL_GOOGLE_include_directive : require
// Texture-space diffusion: the character's mesh unwrapped into its maps. The
// position is the atlas UV (d'Eon's and Gosselin's "texture coordinates as
// position"), mapped onto the viewport, which is the depth-sized map (eq. 3.2).
// Visibility is computed per vertex and interpolated (Listing 3.1, with
// Gosselin's per-vertex view vector); the clip distances are eq. 3.4's.
#include "frame_uniforms.glsl"
#include "tsd_character.glsl"
layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec2 inUv;
layout(location = 3) in vec4 inTangent; // w: handedness x (1 + atlas island)
layout(location = 0) out vec3 vWorldPos;
layout(location = 1) out vec3 vNormal;
layout(location = 2) out vec4 vTangent;
layout(location = 3) out vec2 vUv;
layout(location = 4) out float vEyeDot;
out gl_PerVertex {
    vec4 gl_Position;
    float gl_ClipDistance[6];
};
void main() {
    vec4 world = ch.model * vec4(inPosition, 1.0);
    mat3 m = mat3(ch.model);
    vec3 n = normalize(m * inNormal);
    vWorldPos = world.xyz;
    vNormal = n;
    float hand = inTangent.w < 0.0 ? -1.0 : 1.0;
    vTangent = vec4(normalize(m * inTangent.xyz), hand);
    vUv = inUv;
    vEyeDot = dot(normalize(frame.cameraPos.xyz - world.xyz), n);
    for (int i = 0; i < 6; i++) {
        gl_ClipDistance[i] = dot(ch.planes[i], world);
    }
    vec4 t = atlas.islands[int(abs(inTangent.w) + 0.5) - 1];
    gl_Position = vec4((inUv * t.x + t.yz) * 2.0 - 1.0, pc.z, 1.0);
}
