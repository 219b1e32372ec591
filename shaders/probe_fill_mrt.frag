#version 450
// Ceiling probe (bench::ceilings): the geometry pass's fill, one constant
// write per fragment to each of its attachments (diffuse and specular
// RGBA16F, linear depth R32F; depth and stencil written by the pipeline).
layout(location = 0) in vec2 vUv;
layout(location = 0) out vec4 outDiffuse;
layout(location = 1) out vec4 outSpecular;
layout(location = 2) out float outDepth;
void main() {
    vec2 p = vUv;
    outDiffuse = vec4(p, 0.5, 1.0);
    outSpecular = vec4(0.25, p, 1.0);
    outDepth = p.x;
}
