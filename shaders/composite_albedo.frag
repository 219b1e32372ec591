#version 450
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_GOOGLE_include_directive : require
// The composite of post-scatter texturing: the scattered light times the
// pixel's albedo, plus the specular target.
#define READ_ALBEDO 1
#include "composite_body.glsl"
