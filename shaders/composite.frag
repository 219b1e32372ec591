#version 450
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_GOOGLE_include_directive : require
// The composite of pre-scatter texturing (composite_body.glsl).
#include "composite_body.glsl"
