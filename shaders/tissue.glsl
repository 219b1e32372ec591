// The tissue test of src/skin/tissue.rs (the module doc says why): whether
// light diffuses from xi (normal ni) to xo (normal no) through tissue. Points
// closer than SAME_POINT_MM are one point. The includer first defines
// TISSUE_MM_PER_UNIT and TISSUE_TOLERANCE_VALUE as the expressions (its uniform
// fields) that hold the scene's millimetres per unit and the tolerance.
#ifndef DERMIS_TISSUE_GLSL
#define DERMIS_TISSUE_GLSL
#include "shader_constants.glsl"
bool throughTissue(vec3 xo, vec3 no, vec3 xi, vec3 ni) {
    vec3 d = xi - xo;
    if (length(d) * TISSUE_MM_PER_UNIT < SAME_POINT_MM) return true;
    float lim = TISSUE_TOLERANCE_VALUE * length(d);
    return dot(d, no) <= lim && -dot(d, ni) <= lim;
}
#endif
