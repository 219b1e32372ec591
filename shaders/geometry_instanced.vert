#version 450
#extension GL_GOOGLE_include_directive : require
#include "frame_uniforms.glsl"
layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec2 inUv;
layout(location = 3) in vec4 inTangent;
// The characters' model matrices, drawn as instances (issue 16 item 7: one
// draw per group, however many characters): gl_InstanceIndex includes the
// draw's first instance, so each group reads its own slice.
layout(std430, set = 2, binding = 0) readonly buffer Instances { mat4 models[]; };
// Each slot's wrinkle zone weights, two vec4 (src/render/instances.rs).
layout(std430, set = 2, binding = 1) readonly buffer Zones { vec4 zones[]; };
layout(location = 0) out vec3 vWorldPos;
layout(location = 1) out vec3 vNormal;
layout(location = 2) out vec4 vTangent;
layout(location = 3) out vec2 vUv;
layout(location = 4) out float vViewDepth;
layout(location = 5) flat out vec4 vZones0;
layout(location = 6) flat out vec4 vZones1;
void main() {
    mat4 model = models[gl_InstanceIndex];
    vec4 world = model * vec4(inPosition, 1.0);
    // Instances are translated and uniformly scaled only: mat3(model) keeps normals normal.
    mat3 m = mat3(model);
    vWorldPos = world.xyz;
    vNormal = normalize(m * inNormal);
    vTangent = vec4(normalize(m * inTangent.xyz), inTangent.w);
    vUv = inUv;
    vViewDepth = -(frame.view * world).z;
    gl_Position = frame.viewProj * world;
    vZones0 = zones[2 * gl_InstanceIndex];
    vZones1 = zones[2 * gl_InstanceIndex + 1];
}
