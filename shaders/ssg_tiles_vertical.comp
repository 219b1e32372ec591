#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
// ssg vertical pass on the compute path: RT2 -> RT1, and RTF (the diffuse
// target) mixed with the constant w'_i (eq. 4.9) as the fragment path's
// blend does: rgb = c w' + rtf (1 - w'), alpha = c's (ssg_tiles.glsl).
#include "ssg_tiles.glsl"
layout(set = 0, binding = 7, rgba16f) uniform image2D finalImage;
void main() {
    COUNT_INVOCATION();
    ivec2 p;
    if (!ssgPixel(p)) return;
    vec4 colorM = COUNTED(SITE(0, 0, FK_POINT), texelFetch(colorTex, p, 0));
    vec4 c = ssgBlurAt(p, colorM);
    imageStore(outImage, p, c);
    vec4 f = imageLoad(finalImage, p);
    vec3 w = pc.center.rgb;
    imageStore(finalImage, p, vec4(c.rgb * w + f.rgb * (vec3(1.0) - w), c.a));
}
