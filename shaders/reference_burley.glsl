// Burley's profile for the ground truth (src/reference/burley.rs, whose f64
// functions these follow line for line): R(r) / A per channel, the integral
// of R / A over a subsample's cell near the pixel's point (the 1/r
// singularity), and the ring weight of a farther subsample.
#ifndef DERMIS_REFERENCE_BURLEY_GLSL
#define DERMIS_REFERENCE_BURLEY_GLSL
#include "shader_constants.glsl"

const vec3 BURLEY_S = BURLEY_S_PER_MM;
const float BURLEY_PI = 3.14159265359;

// R(r) / A per channel (per mm^2).
vec3 burleyProfile(float r) {
    return BURLEY_S * (exp(-BURLEY_S * r) + exp(-BURLEY_S * r / 3.0)) / (8.0 * BURLEY_PI * r);
}

// 1 - e^(-x) without the cancellation of small x.
vec3 burleyOneMinusExp(vec3 x) {
    vec3 series = x * (1.0 - x * (0.5 - x / 6.0));
    return mix(1.0 - exp(-x), series, lessThan(x, vec3(1e-2)));
}

// Antiderivative of 1/r: x asinh(y / |x|) + y asinh(x / |y|).
float burleyInvR(float x, float y) {
    float a = x != 0.0 ? x * asinh(y / abs(x)) : 0.0;
    float b = y != 0.0 ? y * asinh(x / abs(y)) : 0.0;
    return a + b;
}

// The integral of R / A over the square cell of side h (mm) at (du, dv) h.
vec3 burleyCellWeight(float du, float dv, float h) {
    float step = 1.0 / float(BURLEY_CELL_PARTS);
    vec3 w = vec3(0.0);
    for (int j = 0; j < BURLEY_CELL_PARTS; j++) {
        float y1 = dv - 0.5 + float(j) * step;
        for (int i = 0; i < BURLEY_CELL_PARTS; i++) {
            float x1 = du - 0.5 + float(i) * step;
            float x2 = x1 + step, y2 = y1 + step;
            float invR = (burleyInvR(x2, y2) - burleyInvR(x1, y2) - burleyInvR(x2, y1) + burleyInvR(x1, y1)) * h;
            float cx = x1 + 0.5 * step, cy = y1 + 0.5 * step;
            float r = sqrt(cx * cx + cy * cy) * h;
            vec3 g = 0.5 * (exp(-BURLEY_S * r) + exp(-BURLEY_S * r / 3.0));
            w += BURLEY_S / (4.0 * BURLEY_PI) * g * invR;
        }
    }
    return w;
}

// A farther subsample (area h^2) at distance r: the ring integral of R / A
// over [r - h/2, r + h/2] times the cell's share of the ring.
vec3 burleyRingWeight(float r, float h) {
    float a = r - 0.5 * h;
    vec3 df = 0.25 * exp(-BURLEY_S * a) * burleyOneMinusExp(BURLEY_S * h)
            + 0.75 * exp(-BURLEY_S * a / 3.0) * burleyOneMinusExp(BURLEY_S * h / 3.0);
    return df * h / (2.0 * BURLEY_PI * r);
}

bool burleyInCellReach(float du, float dv) {
    float reach = float(BURLEY_CELL_REACH) + 0.5;
    return abs(du) <= reach && abs(dv) <= reach;
}
#endif
