#version 450
// Ceiling probe (bench::ceilings): the triangle rate. Triangle t of the draw
// sits in pixel (t mod W, t / W mod H) of the W x H target, a right triangle
// of legs 0.4 px in the pixel's upper left corner past its centre, so it
// covers no sample: the set-up and rasteriser's rate alone, triangles spread
// over the whole screen as a dense mesh's are. No vertex buffer.
layout(push_constant) uniform Push { vec2 texel; int taps; int pad; } pc;
// What fullscreen.vert passes, for the fill probe's fragment shader.
layout(location = 0) out vec2 vUv;
void main() {
    uint t = uint(gl_VertexIndex) / 3u;
    uint corner = uint(gl_VertexIndex) % 3u;
    uvec2 wh = uvec2(round(1.0 / pc.texel));
    uvec2 pixel = uvec2(t % wh.x, (t / wh.x) % wh.y);
    // Corners at (0.55, 0.55), (0.95, 0.55), (0.55, 0.95) of the pixel: the
    // centre (0.5, 0.5) is outside, and so is every other pixel's.
    vec2 at = vec2(pixel) + vec2(0.55) + 0.4 * vec2(corner == 1u, corner == 2u);
    vUv = at * pc.texel;
    gl_Position = vec4(vUv * 2.0 - 1.0, 0.5, 1.0);
}
