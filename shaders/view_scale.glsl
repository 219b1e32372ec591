// The view's scale as src/view/mod.rs (ViewScale) computes it, in the same
// order of products (the images are hashed bit for bit).
#ifndef DERMIS_VIEW_SCALE_GLSL
#define DERMIS_VIEW_SCALE_GLSL
// Scene units the screen's height spans at view depth `depth`: 2 depth tan(fovy/2).
#define SCREEN_HEIGHT_UNITS(depth, tanHalfFovy) (2.0 * (depth) * (tanHalfFovy))
// Pixels per millimetre at view depth `depth`: height / (2 depth tan(fovy/2) mm_per_unit).
#define PX_PER_MM(heightPx, depth, tanHalfFovy, mmPerUnit) ((heightPx) / (SCREEN_HEIGHT_UNITS(depth, tanHalfFovy) * (mmPerUnit)))
#endif
