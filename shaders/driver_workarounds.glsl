#ifndef DERMIS_DRIVER_WORKAROUNDS_GLSL
#define DERMIS_DRIVER_WORKAROUNDS_GLSL
// Driver workarounds shared by the shaders (fragment stage).
//
// lavapipe in Mesa 22.3 (Debian 12's) compiles a fresh copy of a fragment shader,
// and never frees it, every time a descriptor set of it is bound, when the shader
// branches on a uniform-buffer value alone (its "inline uniforms" optimisation
// bakes the value in per bind): the geometry pass leaked two shaders, 2.5 MB, per
// frame. Adding NOT_UNIFORM_ZERO to such a value keeps the branch off that list:
// fragment coordinates are never negative, so it is exactly 0 in every fragment,
// but the driver cannot know that. See docs/reliability.md and
// tools/examples/lavapipe_inline_leak.rs (the minimal program).
#define NOT_UNIFORM_ZERO min(gl_FragCoord.x, 0.0)
#endif
