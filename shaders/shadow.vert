#version 450
// Key-light depth: an orthographic projection, so the stored depth is linear in
// distance along the light (transmittance reads distances from it).
layout(location = 0) in vec3 inPosition;
layout(push_constant) uniform Push { mat4 model; mat4 lightViewProj; } pc;
void main() {
    gl_Position = pc.lightViewProj * pc.model * vec4(inPosition, 1.0);
}
