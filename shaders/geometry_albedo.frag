#version 450
#extension GL_GOOGLE_include_directive : require
// The geometry pass of post-scatter texturing: a fourth target with the
// albedo, which the composite multiplies in after the SSS.
#define WRITE_ALBEDO 3
#include "geometry_body.glsl"
