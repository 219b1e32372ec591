#version 450
// Key-light depth: an orthographic projection, so the stored depth is linear in
// distance along the light (transmittance reads distances from it).
layout(location = 0) in vec3 inPosition;
// Every character's model matrix, drawn as instances (one draw for all heads).
layout(std430, set = 0, binding = 0) readonly buffer Instances { mat4 models[]; };
layout(push_constant) uniform Push { mat4 lightViewProj; } pc;
void main() {
    gl_Position = pc.lightViewProj * models[gl_InstanceIndex] * vec4(inPosition, 1.0);
}
