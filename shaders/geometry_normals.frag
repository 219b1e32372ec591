#version 450
#extension GL_GOOGLE_include_directive : require
// The geometry pass plus a fourth target with the view-space normal (poisson).
#define WRITE_NORMALS 1
#include "geometry_body.glsl"
