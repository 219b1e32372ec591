#version 450
#extension GL_GOOGLE_include_directive : require
// The geometry pass with the normal target (poisson) and, fifth, the albedo
// of post-scatter texturing.
#define WRITE_NORMALS 1
#define WRITE_ALBEDO 4
#include "geometry_body.glsl"
