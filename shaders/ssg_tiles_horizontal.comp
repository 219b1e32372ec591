#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
// ssg horizontal pass on the compute path: RT1 -> RT2 (ssg_tiles.glsl).
#include "ssg_tiles.glsl"
void main() {
    COUNT_INVOCATION();
    ivec2 p;
    if (!ssgPixel(p)) return;
    vec4 colorM = COUNTED(SITE(0, 0, FK_POINT), texelFetch(colorTex, p, 0));
    imageStore(outImage, p, ssgBlurAt(p, colorM));
}
