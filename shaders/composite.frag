#version 450
// Adds the specular target to the (scattered) diffuse one, linear HDR.
layout(set = 0, binding = 0) uniform sampler2D diffuseTex;
layout(set = 0, binding = 1) uniform sampler2D specularTex;
layout(location = 0) in vec2 vUv;
layout(location = 0) out vec4 outColor;
void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    outColor = vec4(texelFetch(diffuseTex, p, 0).rgb + texelFetch(specularTex, p, 0).rgb, 1.0);
}
