#version 450
// Ceiling probe: fill rate, one constant write per fragment.
layout(location = 0) in vec2 vUv;
layout(location = 0) out vec4 outColor;
void main() { outColor = vec4(vUv, 0.5, 1.0); }
