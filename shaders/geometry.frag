#version 450
#extension GL_GOOGLE_include_directive : require
// Geometry pass: diffuse (Lambert x albedo, plus transmittance, thesis ch. 5) into
// an RGBA16F target whose alpha is the per-pixel SSS strength (0 on non-skin),
// Kelemen/Szirmay-Kalos specular into a second target, linear view depth into a third.
#include "geometry_body.glsl"
