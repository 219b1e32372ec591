//! The CPU mirrors of texture-space diffusion's GPU passes (`method::tsd`):
//! which triangle holds each texel and which texels each optimisation keeps
//! (the prediction the culled, clipped and pre-passed maps are held to), and
//! the convolution chain as the GPU runs it (normalised convolution on
//! premultiplied coverage, Vulkan bilinear taps, 16-bit float stores) with the
//! final look-up. The geometry they follow is in [`super::tsd`].

use glam::{Mat4, Vec3, Vec4};

use super::ssg::LISTING_4_1_WEIGHTS;
use super::texel::{bilinear4, round_f16_with, F16Rounding};
use super::tsd::{cross2, span, tsd_gaussians, EDGE_GUARD_TEXELS};
use crate::scene::mesh::Mesh;

// --- Which triangle holds each texel, and what it interpolates ----------------------

/// The triangle whose UV interior holds a texel centre, with the centre's
/// barycentric coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TexelHit {
    pub tri: usize,
    pub bary: [f32; 3],
}

/// For each texel of a `size`^2 viewport, a triangle holding its centre (edges
/// included, within `eps` of barycentric): what the rasteriser interpolates
/// there. (Coverage itself follows the device's tie rules: take it from a
/// render.)
pub fn texel_hits(uv: &[[f32; 2]], indices: &[u32], size: u32, eps: f32) -> Vec<Option<TexelHit>> {
    let n = size as f32;
    let mut out = vec![None; (size * size) as usize];
    for (t, tri) in indices.chunks_exact(3).enumerate() {
        let [a, b, c] = [0, 1, 2].map(|i| uv[tri[i] as usize]);
        let area = cross2(a, b, c);
        if area == 0.0 {
            continue;
        }
        let (x0, x1) = span(a[0], b[0], c[0], size);
        let (y0, y1) = span(a[1], b[1], c[1], size);
        for y in y0..y1 {
            for x in x0..x1 {
                let i = y as usize * size as usize + x as usize;
                if out[i].is_some() {
                    continue;
                }
                let p = [(x as f32 + 0.5) / n, (y as f32 + 0.5) / n];
                let w = [
                    cross2(b, c, p) / area,
                    cross2(c, a, p) / area,
                    cross2(a, b, p) / area,
                ];
                if w.iter().all(|&e| e >= -eps) {
                    out[i] = Some(TexelHit { tri: t, bary: w });
                }
            }
        }
    }
    out
}

/// What the UV-space vertex shader computes per vertex and the rasteriser
/// interpolates: the eye-dot `N.V` (Listing 3.1 with Gosselin's per-vertex view
/// vector) and the six clip distances (eq. 3.4).
#[derive(Clone, Debug)]
pub struct VertexTerms {
    pub eye_dot: Vec<f32>,
    pub clip: Vec<[f32; 6]>,
}

impl VertexTerms {
    /// From the mesh, the character's model matrix (translation and uniform
    /// scale), the eye and the planes, in f32 as the shader does it.
    pub fn new(mesh: &Mesh, model: Mat4, eye: Vec3, planes: &[Vec4; 6]) -> Self {
        let m3 = glam::Mat3::from_mat4(model);
        let mut eye_dot = Vec::with_capacity(mesh.vertices.len());
        let mut clip = Vec::with_capacity(mesh.vertices.len());
        for v in &mesh.vertices {
            let w = model * Vec3::from(v.position).extend(1.0);
            let n = (m3 * Vec3::from(v.normal)).normalize_or_zero();
            let view = (eye - w.truncate()).normalize_or_zero();
            eye_dot.push(view.dot(n));
            clip.push(planes.map(|p| p.dot(w)));
        }
        VertexTerms { eye_dot, clip }
    }

    /// The interpolated eye-dot and clip distances at a texel.
    pub fn at(&self, hit: &TexelHit, indices: &[u32]) -> (f32, [f32; 6]) {
        let ix = &indices[3 * hit.tri..3 * hit.tri + 3];
        let b = hit.bary;
        let e = (0..3).map(|k| b[k] * self.eye_dot[ix[k] as usize]).sum();
        let mut c = [0.0; 6];
        for (j, cj) in c.iter_mut().enumerate() {
            *cj = (0..3).map(|k| b[k] * self.clip[ix[k] as usize][j]).sum();
        }
        (e, c)
    }
}

/// Which tests a texel must pass to be kept.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KeepRule {
    /// Eye-dot at least this (the 105 degree cull, or `-BACKFACE_BIAS`).
    pub min_eye_dot: Option<f32>,
    /// Inside the six planes.
    pub clip: bool,
}

/// Whether a texel is kept: `Some(keep)`, or `None` when a quantity lies
/// within `eps` of its threshold (the device's interpolation may fall on either side).
pub fn keeps(rule: KeepRule, eye_dot: f32, clip: &[f32; 6], eps: f32) -> Option<bool> {
    let mut tests = Vec::new();
    if let Some(t) = rule.min_eye_dot {
        tests.push(eye_dot - t);
    }
    if rule.clip {
        tests.extend(clip.iter().copied());
    }
    if tests.iter().any(|&d| d.abs() < eps) {
        return None;
    }
    Some(tests.iter().all(|&d| d >= 0.0))
}

// --- The convolution chain ------------------------------------------------------------

/// The texture-space maps one character's chain starts from (row-major,
/// `size`^2, as the irradiance pass leaves them).
#[derive(Clone, Copy, Debug)]
pub struct ChainInput<'a> {
    /// Side of the map images (T_max).
    pub size: usize,
    /// Side of the square the passes work in (T, eq. 3.2).
    pub area: usize,
    /// Irradiance with premultiplied coverage (rgb * a, a).
    pub irradiance: &'a [[f32; 4]],
    pub stretch_u: &'a [f32],
    pub stretch_v: &'a [f32],
    /// Texels the passes shade (depth/stencil mask); `None`: all of the area.
    pub shaded: Option<&'a [bool]>,
    /// Listing 3.3: a texel whose source alpha is 0 writes 0 and fetches nothing more.
    pub alpha_test: bool,
    pub rounding: F16Rounding,
}

/// The chain's result: every pass's output, and the accumulated map.
#[derive(Clone, Debug)]
pub struct ChainOutput {
    /// After each of the twelve passes (u then v per Gaussian).
    pub passes: Vec<Vec<[f32; 4]>>,
    /// The final map: `sum_i w_i G_i / a_i` blended by eq. 4.9, alpha 1 where valid.
    pub map: Vec<[f32; 4]>,
}

/// One 7-tap pass of Listing 4.1 along `axis` (0: u, 1: v) with the step
/// `stretch * std_mm` texels, taps clamped into the working square.
fn blur_pass(
    input: &ChainInput,
    src: &[[f32; 4]],
    stretch: &[f32],
    axis: usize,
    std_mm: f32,
    prev: &[[f32; 4]],
) -> Vec<[f32; 4]> {
    let n = input.size;
    let inv = 1.0 / n as f32;
    let lo = 0.5 * inv;
    let hi = (input.area as f32 - 0.5 - EDGE_GUARD_TEXELS) * inv;
    let w = LISTING_4_1_WEIGHTS;
    let mut out = prev.to_vec();
    for y in 0..input.area {
        for x in 0..input.area {
            let i = y * n + x;
            if input.shaded.is_some_and(|m| !m[i]) {
                continue;
            }
            let c = src[i];
            if input.alpha_test && c[3] <= 0.0 {
                out[i] = [0.0; 4];
                continue;
            }
            let uv = [(x as f32 + 0.5) * inv, (y as f32 + 0.5) * inv];
            let step = stretch[i] * std_mm * inv;
            let mut acc = c.map(|v| w[3] * v);
            for k in 1..=3 {
                for sgn in [-1.0f32, 1.0] {
                    let mut t = uv;
                    t[axis] += sgn * k as f32 * step;
                    let t = t.map(|v| v.clamp(lo, hi));
                    let s = bilinear4(src, n, n, t[0], t[1]);
                    let wk = w[3 + k];
                    for ch in 0..4 {
                        acc[ch] += wk * s[ch];
                    }
                }
            }
            out[i] = round_f16_with(acc, input.rounding);
        }
    }
    out
}

/// The whole chain: for each Gaussian a pass along u into the temporary and
/// one along v back, the v pass also blending `G_i / a_i` into the map with
/// `w'_i` (eq. 4.9). Texels outside the mask keep what they held (zeros from
/// the clears); `prev_map` is the map before the chain.
pub fn blur_chain(input: &ChainInput, prev_map: &[[f32; 4]]) -> ChainOutput {
    let n = input.size * input.size;
    let mut cur = input.irradiance.to_vec();
    let mut temp = vec![[0.0f32; 4]; n];
    let mut pong = vec![[0.0f32; 4]; n];
    let mut map = prev_map.to_vec();
    let mut passes = Vec::new();
    for (gi, g) in tsd_gaussians().into_iter().enumerate() {
        temp = blur_pass(input, &cur, input.stretch_u, 0, g.std_mm, &temp);
        passes.push(temp.clone());
        let next = blur_pass(input, &temp, input.stretch_v, 1, g.std_mm, &pong);
        for y in 0..input.area {
            for x in 0..input.area {
                let i = y * input.size + x;
                if input.shaded.is_some_and(|m| !m[i]) {
                    continue;
                }
                let r = next[i];
                let src = if r[3] > 0.0 {
                    [r[0] / r[3], r[1] / r[3], r[2] / r[3], 1.0]
                } else {
                    [0.0; 4]
                };
                let b = g.blend;
                let d = map[i];
                let mixed = if gi == 0 {
                    src
                } else {
                    [
                        src[0] * b[0] + d[0] * (1.0 - b[0]),
                        src[1] * b[1] + d[1] * (1.0 - b[1]),
                        src[2] * b[2] + d[2] * (1.0 - b[2]),
                        src[3],
                    ]
                };
                map[i] = round_f16_with(mixed, input.rounding);
            }
        }
        passes.push(next.clone());
        // The v pass writes the buffer the irradiance was not read from last.
        pong = std::mem::replace(&mut cur, next);
    }
    ChainOutput { passes, map }
}

/// The final look-up: the map's bilinear value at `uv` (atlas) scaled into
/// the working square, divided by its coverage; `None` where nothing valid is near.
pub fn final_lookup(map: &[[f32; 4]], size: usize, area: usize, uv: [f32; 2]) -> Option<[f32; 3]> {
    let inv = 1.0 / size as f32;
    let s = area as f32 * inv;
    let (lo, hi) = (0.5 * inv, (area as f32 - 0.5 - EDGE_GUARD_TEXELS) * inv);
    let t = uv.map(|v| (v * s).clamp(lo, hi));
    let m = bilinear4(map, size, size, t[0], t[1]);
    (m[3] > 1e-3).then(|| [m[0] / m[3], m[1] / m[3], m[2] / m[3]])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::skin::tsd::CULL_COS;

    // A constant map with a hole: every written texel stays the constant
    // (no background pulled in at the seam), texels nobody wrote stay 0.
    #[test]
    fn the_chain_keeps_a_constant_up_to_the_seams() {
        let n = 32;
        let mut irr = vec![[0.0f32; 4]; n * n];
        for y in 0..n {
            for x in 0..n {
                if (x as i32 - 16).pow(2) + (y as i32 - 16).pow(2) < 100 || x < 4 {
                    irr[y * n + x] = [0.5, 0.25, 0.125, 1.0];
                }
            }
        }
        let st = vec![1.5f32; n * n];
        let input = ChainInput {
            size: n,
            area: n,
            irradiance: &irr,
            stretch_u: &st,
            stretch_v: &st,
            shaded: None,
            alpha_test: false,
            rounding: F16Rounding::NearestEven,
        };
        let out = blur_chain(&input, &vec![[0.0; 4]; n * n]);
        assert_eq!(out.passes.len(), 12);
        for (i, (p, m)) in irr.iter().zip(&out.map).enumerate() {
            if p[3] > 0.0 {
                assert_eq!(m[3], 1.0);
                for (c, want) in [0.5f32, 0.25, 0.125].iter().enumerate() {
                    assert!((m[c] - want).abs() <= 2e-3 * want, "{i}: {m:?}");
                }
            }
        }
        // And a texel written in a blurred irradiance differs from its neighbours'
        // mean only by the blur: an impulse spreads to the expected variance.
        let mut imp = vec![[0.0f32, 0.0, 0.0, 1.0]; n * n];
        imp[16 * n + 16] = [1.0, 1.0, 1.0, 1.0];
        let one = vec![1.0f32; n * n];
        let input = ChainInput {
            irradiance: &imp,
            stretch_u: &one,
            stretch_v: &one,
            ..input
        };
        let out = blur_chain(&input, &vec![[0.0; 4]; n * n]);
        // Red after all six: variance sum_i w_i v_i per axis (texel = 1 mm),
        // plus the bilinear taps' own spread.
        let m = &out.map;
        let (mut s0, mut s2) = (0.0f64, 0.0f64);
        for x in 0..n {
            let v = m[16 * n + x][0] as f64;
            s0 += v;
            s2 += v * (x as f64 - 16.0).powi(2);
        }
        assert!(s0 > 0.0);
        let var = s2 / s0;
        assert!(var > 0.1 && var < 4.0, "{var}");
    }

    #[test]
    fn texel_hits_interpolate_and_keep_rules_flag_ties() {
        let uv = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
        let hits = texel_hits(&uv, &[0, 1, 2], 4, 1e-6);
        assert!(hits[0].is_some() && hits[15].is_none());
        let h = hits[0].unwrap();
        assert!((h.bary.iter().sum::<f32>() - 1.0).abs() < 1e-6);
        let rule = KeepRule {
            min_eye_dot: Some(CULL_COS),
            clip: true,
        };
        assert_eq!(keeps(rule, 0.5, &[1.0; 6], 1e-4), Some(true));
        assert_eq!(keeps(rule, -0.5, &[1.0; 6], 1e-4), Some(false));
        assert_eq!(
            keeps(rule, 0.5, &[1.0, 1.0, -0.1, 1.0, 1.0, 1.0], 1e-4),
            Some(false)
        );
        assert_eq!(keeps(rule, CULL_COS, &[1.0; 6], 1e-4), None);
    }
}
