#version 450
#extension GL_EXT_samplerless_texture_functions : require
// Ground truth, step 2: for every skin pixel, the radiant exitance
// M(x_o) = sum_j L_d(x_j) R(|x_j - x_o|) dA_j over all surface samples within the
// cut-off (true 3D distances, visible or not), R the six-Gaussian profile. The two
// narrowest Gaussians (sigma <= 0.22 mm, below the sample spacing) are taken as
// w_i L_d(x_o): the surface is locally flat and uniformly lit at that scale.
layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform texture2D diffuseTex;  // L_d(x_o) (no transmittance), alpha = strength
layout(set = 0, binding = 1) uniform texture2D depthTex;    // linear view depth
layout(set = 0, binding = 2, rgba32f) uniform writeonly image2D outImage;
struct Sample { vec4 posArea; vec4 normal; vec4 tangent; vec4 uv; };
layout(std430, set = 0, binding = 3) readonly buffer Samples { Sample samples[]; };
layout(set = 0, binding = 4) uniform texture2D radianceTex;  // sample i at (i % width, i / width)
layout(std430, set = 0, binding = 5) readonly buffer Cells { uint cellStart[]; };
layout(set = 0, binding = 6) uniform GatherParams {
    mat4 invView;
    vec4 gridOrigin;   // xyz; w: cell size (scene units)
    uvec4 gridDims;    // xyz; w: width of the radiance texture
    vec4 view;         // x: tan(fovy/2), y: aspect, z: mm per unit, w: cut-off radius (mm)
} params;

// Six-Gaussian skin profile (thesis Table 4.2), variances in mm^2.
const vec3 W_NARROW = vec3(0.233 + 0.1, 0.455 + 0.336, 0.649 + 0.344);
const vec3 W3 = vec3(0.118, 0.198, 0.0);
const vec3 W4 = vec3(0.113, 0.007, 0.007);
const vec3 W5 = vec3(0.358, 0.004, 0.0);
const vec3 W6 = vec3(0.078, 0.0, 0.0);
const float TWO_PI = 6.28318530718;

vec3 wideProfile(float r2) {
    return W3 * (exp(-r2 / (2.0 * 0.187)) / (TWO_PI * 0.187)) +
           W4 * (exp(-r2 / (2.0 * 0.567)) / (TWO_PI * 0.567)) +
           W5 * (exp(-r2 / (2.0 * 1.99)) / (TWO_PI * 1.99)) +
           W6 * (exp(-r2 / (2.0 * 7.41)) / (TWO_PI * 7.41));
}

void main() {
    ivec2 size = textureSize(diffuseTex, 0);
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= size.x || p.y >= size.y) return;
    vec4 d0 = texelFetch(diffuseTex, p, 0);
    if (d0.a <= 0.0) {
        imageStore(outImage, p, d0);
        return;
    }
    float z = texelFetch(depthTex, p, 0).r;
    vec2 ndc = (vec2(p) + 0.5) / vec2(size) * 2.0 - 1.0;
    vec3 viewPos = vec3(ndc.x * params.view.x * params.view.y * z, -ndc.y * params.view.x * z, -z);
    vec3 xo = (params.invView * vec4(viewPos, 1.0)).xyz;
    float mm = params.view.z;
    float cutoff2 = params.view.w * params.view.w;
    ivec3 c = ivec3(floor((xo - params.gridOrigin.xyz) / params.gridOrigin.w));
    ivec3 dims = ivec3(params.gridDims.xyz);
    vec3 acc = W_NARROW * d0.rgb;
    for (int dz = -1; dz <= 1; dz++)
    for (int dy = -1; dy <= 1; dy++)
    for (int dx = -1; dx <= 1; dx++) {
        ivec3 q = c + ivec3(dx, dy, dz);
        if (any(lessThan(q, ivec3(0))) || any(greaterThanEqual(q, dims))) continue;
        uint cell = uint((q.z * dims.y + q.y) * dims.x + q.x);
        for (uint j = cellStart[cell]; j < cellStart[cell + 1u]; j++) {
            vec4 pa = samples[j].posArea;
            vec3 dv = (pa.xyz - xo) * mm;
            float r2 = dot(dv, dv);
            if (r2 > cutoff2) continue;
            vec3 radiance = texelFetch(radianceTex, ivec2(j % params.gridDims.w, j / params.gridDims.w), 0).rgb;
            acc += pa.w * radiance * wideProfile(r2);
        }
    }
    imageStore(outImage, p, vec4(acc, d0.a));
}
