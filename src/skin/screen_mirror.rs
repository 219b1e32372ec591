//! CPU mirrors of the single-pass screen-space SSS variants: the
//! jittered 13-tap kernel (Hable et al., thesis' "SS Jittered") and the
//! Poisson-disk kernel with depth/normal-aware weights (seed 003), plus the
//! device rules they follow are in [`super::texel`].
//!
//! As in [`super::separable_mirror`], every operation mirrors the shader: f32
//! arithmetic in the stated order, Vulkan bilinear filtering with
//! CLAMP_TO_EDGE, and rounding through f16 after every write to an RGBA16F
//! target, so GPU and CPU images can be compared per pixel.
//!
//! Conventions: images are row-major `width x height`; the uv of pixel
//! `(x, y)` is `((x + 0.5)/width, (y + 0.5)/height)`; non-skin pixels are
//! never written.

use std::f32::consts::PI;

use super::jittered::{jitter_angle, JitteredKernel};
use super::mirror::MirrorInput;
use super::poisson::{count_index, mip_level, poisson_disk_32, sample_count, PoissonParams};
use super::ssg::Stretch;
use super::texel::{
    bilinear4, bilinear_lod1, bilinear_lod4, mip_chain1, mip_chain4_with, pixel_uv, round_f16,
    round_f16_with, F16Rounding,
};

/// Screen-space adaptation of Hable et al.'s jittered 13-tap kernel.
///
/// Per skin pixel `p = (x, y)`:
/// * `colorM = src[p]` where `src` is a copy of the diffuse image (the GPU
///   seeds an intermediate target with a copy and samples that);
/// * `[s_x, s_y] = stretch.factors(..) * colorM.a` (eq. 4.1-4.4);
/// * `theta = jitter_angle(x, y)`; mid ring `k = 0..6`: angle
///   `a = theta + k * PI/3`, radius `mid_radius_mm`; wide ring: angle
///   `theta + PI/6 + k * PI/3`, radius `wide_radius_mm`;
/// * mm offset `(cos a * r, sin a * r)`; pixel offset
///   `(ox * s_x / 3, oy * s_y / 3)` (Listing 4.1: one mm of sigma spans
///   `s/3` pixels); uv offset `px / (width, height)`; `c = bilinear4(src,
///   uv + off)`;
/// * `out.rgb = center * colorM.rgb + sum_mid (mid/6) c + sum_wide (wide/6) c`,
///   accumulated in that order (centre, then the six mid taps, then the six
///   wide taps); `out.a = colorM.a`; stored as f16.
pub fn jittered(input: &MirrorInput, kernel: &JitteredKernel, stretch: Stretch) -> Vec<[f32; 4]> {
    input.check();
    let (w, h) = (input.width, input.height);
    let src = input.diffuse;
    let mut out = input.diffuse.to_vec();
    let mid_w = kernel.mid.map(|m| m / 6.0);
    let wide_w = kernel.wide.map(|m| m / 6.0);
    for y in 0..h {
        for x in 0..w {
            let p = y * w + x;
            if !input.skin[p] {
                continue;
            }
            let color_m = src[p];
            let [sx, sy] = stretch.factors(input.linear_depth, w, h, x, y);
            let (sx, sy) = (sx * color_m[3], sy * color_m[3]);
            let [u, v] = pixel_uv(x, y, w, h);
            let theta = jitter_angle(x as u32, y as u32);
            let mut acc = [0.0f32; 3];
            for c in 0..3 {
                acc[c] = kernel.center[c] * color_m[c];
            }
            let mut ring = |phase: f32, radius: f32, weight: [f32; 3]| {
                for k in 0..6 {
                    let a = theta + phase + k as f32 * (PI / 3.0);
                    let (ox, oy) = (a.cos() * radius, a.sin() * radius);
                    let (px, py) = (ox * sx / 3.0, oy * sy / 3.0);
                    let s = bilinear4(src, w, h, u + px / w as f32, v + py / h as f32);
                    for c in 0..3 {
                        acc[c] += weight[c] * s[c];
                    }
                }
            };
            ring(0.0, kernel.mid_radius_mm, mid_w);
            ring(PI / 6.0, kernel.wide_radius_mm, wide_w);
            out[p] = round_f16([acc[0], acc[1], acc[2], color_m[3]]);
        }
    }
    out
}

/// Poisson-disk SSS (seed 003's pseudo code) with mip-mapped fetches.
///
/// Chains of `levels` levels are built from the diffuse (RGBA16F), depth
/// (R32F) and normal (RGBA16F) images with [`mip_chain4`]/[`mip_chain1`].
/// Per skin pixel:
/// * `colorM = diffuse[p]`, `d = depth[p]`, `n = normals level 0 [p].xyz`
///   (the f16-rounded normal, as the GPU reads it from its RGBA16F target);
/// * `R_px = radius_mm / (mm_per_unit * 2 * d * tan(fovy/2)) * height * colorM.a`
///   evaluated left to right as written (the kernel radius in pixels: one
///   pixel covers `mm_per_unit * 2 d tan(fovy/2) / height` mm);
/// * `N = sample_count(R_px)`, `lod = mip_level(R_px, levels - 1)`;
/// * `acc = colorM.rgb`, `total = 1`; for each of the first `N` disk points
///   `q_i`: `uv_s = uv + (q_i.x R_px / width, q_i.y R_px / height)`;
///   `c`, `ds`, `ns` bilinear on level `lod`; `dD = (ds - d) * mm_per_unit`;
///   `wc = c.a * exp(-depth_sensitivity dD^2) *
///   exp(-normal_sensitivity (1 - clamp(dot(ns, n), 0, 1)))`; per channel
///   `w = wc * exp(-falloff[count_index(N)]_c * (q.x^2 + q.y^2))`, `acc += c * w`,
///   `total += w`;
/// * `out.rgb = acc / total`, `out.a = colorM.a`, stored as f16.
pub fn poisson(
    input: &MirrorInput,
    normals: &[[f32; 4]],
    params: &PoissonParams,
    fovy_rad: f32,
    mm_per_unit: f32,
    levels: u32,
) -> Vec<[f32; 4]> {
    poisson_with_rounding(
        input,
        normals,
        params,
        fovy_rad,
        mm_per_unit,
        levels,
        F16Rounding::NearestEven,
    )
}

/// [`poisson`] with the device's f16 store rounding (mip levels and output).
#[allow(clippy::too_many_arguments)]
pub fn poisson_with_rounding(
    input: &MirrorInput,
    normals: &[[f32; 4]],
    params: &PoissonParams,
    fovy_rad: f32,
    mm_per_unit: f32,
    levels: u32,
    rounding: F16Rounding,
) -> Vec<[f32; 4]> {
    input.check();
    let (w, h) = (input.width, input.height);
    assert_eq!(normals.len(), w * h, "normals size");
    let color_chain = mip_chain4_with(input.diffuse, w, h, levels, Some(rounding));
    let depth_chain = mip_chain1(input.linear_depth, w, h, levels);
    let normal_chain = mip_chain4_with(normals, w, h, levels, Some(rounding));
    let disk = poisson_disk_32();
    let tan_half = crate::view::tan_half(fovy_rad);
    let mut out = input.diffuse.to_vec();
    for y in 0..h {
        for x in 0..w {
            let p = y * w + x;
            if !input.skin[p] {
                continue;
            }
            let color_m = input.diffuse[p];
            let d = input.linear_depth[p];
            let n = normal_chain[0].2[p];
            // poisson.frag's own order of products (not ViewScale::px_per_mm's):
            // the mirror rounds as the shader does.
            let r_px =
                params.radius_mm / (mm_per_unit * 2.0 * d * tan_half) * h as f32 * color_m[3];
            let count = sample_count(r_px) as usize;
            let falloff = params.falloff[count_index(count as u32)];
            let lod = mip_level(r_px, levels - 1);
            let [u, v] = pixel_uv(x, y, w, h);
            let mut acc = [color_m[0], color_m[1], color_m[2]];
            let mut total = [1.0f32; 3];
            for q in &disk[..count] {
                let (us, vs) = (u + q[0] * r_px / w as f32, v + q[1] * r_px / h as f32);
                let c = bilinear_lod4(&color_chain, lod, us, vs);
                let ds = bilinear_lod1(&depth_chain, lod, us, vs);
                let ns = bilinear_lod4(&normal_chain, lod, us, vs);
                let dd = (ds - d) * mm_per_unit;
                let dot = ns[0] * n[0] + ns[1] * n[1] + ns[2] * n[2];
                let wc = c[3]
                    * (-params.depth_sensitivity * dd * dd).exp()
                    * (-params.normal_sensitivity * (1.0 - dot.clamp(0.0, 1.0))).exp();
                let r2 = q[0] * q[0] + q[1] * q[1];
                for ch in 0..3 {
                    let wch = wc * (-falloff[ch] * r2).exp();
                    acc[ch] += c[ch] * wch;
                    total[ch] += wch;
                }
            }
            out[p] = round_f16_with(
                [
                    acc[0] / total[0],
                    acc[1] / total[1],
                    acc[2] / total[2],
                    color_m[3],
                ],
                rounding,
            );
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::super::jittered::hable_kernel;
    use super::*;

    /// Deterministic pseudo-random f16-representable colours in [0, 1).
    fn noise_image(n: usize, alpha: f32) -> Vec<[f32; 4]> {
        let mut state = 0x2545_f491_u32;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            (state >> 8) as f32 / (1u32 << 24) as f32
        };
        (0..n)
            .map(|_| round_f16([next(), next(), next(), alpha]))
            .collect()
    }

    fn assert_close(a: &[[f32; 4]], b: &[[f32; 4]], rel: f32) {
        for (i, (x, y)) in a.iter().zip(b).enumerate() {
            for c in 0..4 {
                assert!(
                    (x[c] - y[c]).abs() <= rel * y[c].abs().max(1e-3),
                    "pixel {i} channel {c}: {x:?} vs {y:?}"
                );
            }
        }
    }

    /// A head-sized view: 1 unit = 230 mm at depth 1 with the thesis' fov.
    fn stretch() -> Stretch {
        Stretch::THESIS
    }

    fn scene(w: usize, h: usize, alpha: f32) -> (Vec<[f32; 4]>, Vec<f32>, Vec<bool>) {
        let diffuse = noise_image(w * h, alpha);
        let depth: Vec<f32> = (0..w * h).map(|i| 1.0 + (i % 5) as f32 * 0.0003).collect();
        let skin: Vec<bool> = (0..w * h).map(|i| (i / 4) % 3 != 0).collect();
        (diffuse, depth, skin)
    }

    #[test]
    fn jittered_leaves_non_skin_untouched_and_blurs_skin() {
        let (w, h) = (24, 20);
        let (diffuse, depth, skin) = scene(w, h, 1.0);
        let input = MirrorInput {
            width: w,
            height: h,
            diffuse: &diffuse,
            linear_depth: &depth,
            skin: &skin,
        };
        let out = jittered(&input, &hable_kernel(), stretch());
        let mut changed = 0;
        for i in 0..w * h {
            if skin[i] {
                changed += usize::from(out[i] != diffuse[i]);
                assert_eq!(out[i][3], diffuse[i][3]);
                assert_eq!(out[i], round_f16(out[i]));
            } else {
                assert_eq!(
                    out[i].map(f32::to_bits),
                    diffuse[i].map(f32::to_bits),
                    "pixel {i}"
                );
            }
        }
        assert!(changed > w * h / 2, "only {changed} skin pixels changed");
    }

    #[test]
    fn jittered_constant_and_zero_strength() {
        let (w, h) = (16, 12);
        let colour = round_f16([0.8, 0.45, 0.3, 1.0]);
        let diffuse = vec![colour; w * h];
        let depth = vec![1.0; w * h];
        let skin = vec![true; w * h];
        let input = MirrorInput {
            width: w,
            height: h,
            diffuse: &diffuse,
            linear_depth: &depth,
            skin: &skin,
        };
        assert_close(
            &jittered(&input, &hable_kernel(), stretch()),
            &diffuse,
            1e-3,
        );
        // Strength 0: every tap lands on the centre texel.
        let flat = noise_image(w * h, 0.0);
        let input = MirrorInput {
            diffuse: &flat,
            ..input
        };
        assert_close(&jittered(&input, &hable_kernel(), stretch()), &flat, 1e-3);
    }

    #[test]
    fn jittered_spreads_a_point_further_in_red() {
        let (w, h) = (41, 41);
        let mut diffuse = vec![[0.0, 0.0, 0.0, 1.0]; w * h];
        let centre = (h / 2) * w + w / 2;
        diffuse[centre] = [1.0, 1.0, 1.0, 1.0];
        // Depth 1 with alpha 31.5: one mm of sigma spans 10.5 pixels.
        let depth = vec![1.0; w * h];
        let skin = vec![true; w * h];
        let input = MirrorInput {
            width: w,
            height: h,
            diffuse: &diffuse,
            linear_depth: &depth,
            skin: &skin,
        };
        let out = jittered(&input, &hable_kernel(), stretch());
        // Red reaches ~2 mm * 10.5 px = ~21 px away; green/blue stay within
        // the mid ring (~0.74 mm = ~8 px).
        let far = |c: usize| {
            (0..w * h)
                .filter(|&i| {
                    let (x, y) = ((i % w) as f32 - 20.0, (i / w) as f32 - 20.0);
                    out[i][c] > 0.0 && (x * x + y * y).sqrt() > 12.0
                })
                .count()
        };
        assert!(far(0) > 0);
        assert_eq!(far(1), 0);
        assert_eq!(far(2), 0);
    }

    fn flat_normals(n: usize) -> Vec<[f32; 4]> {
        vec![[0.0, 0.0, 1.0, 0.0]; n]
    }

    #[test]
    fn poisson_leaves_non_skin_untouched_and_blurs_skin() {
        let (w, h) = (32, 24);
        let (diffuse, depth, skin) = scene(w, h, 1.0);
        let input = MirrorInput {
            width: w,
            height: h,
            diffuse: &diffuse,
            linear_depth: &depth,
            skin: &skin,
        };
        let params = PoissonParams::from_profile();
        let out = poisson(
            &input,
            &flat_normals(w * h),
            &params,
            20f32.to_radians(),
            10.0,
            4,
        );
        let mut changed = 0;
        for i in 0..w * h {
            if skin[i] {
                changed += usize::from(out[i] != diffuse[i]);
                assert_eq!(out[i][3], diffuse[i][3]);
            } else {
                assert_eq!(out[i].map(f32::to_bits), diffuse[i].map(f32::to_bits));
            }
        }
        assert!(changed > w * h / 2, "only {changed} skin pixels changed");
    }

    #[test]
    fn poisson_keeps_a_constant_image_constant() {
        let (w, h) = (40, 30);
        let colour = round_f16([0.8, 0.45, 0.3, 1.0]);
        let diffuse = vec![colour; w * h];
        let skin = vec![true; w * h];
        // Varying depth and normals only change weights, not the average.
        let depth: Vec<f32> = (0..w * h).map(|i| 0.5 + (i % 7) as f32 * 0.01).collect();
        let normals: Vec<[f32; 4]> = (0..w * h)
            .map(|i| {
                let a = (i % 11) as f32 * 0.1;
                round_f16([a.sin(), 0.0, a.cos(), 0.0])
            })
            .collect();
        let input = MirrorInput {
            width: w,
            height: h,
            diffuse: &diffuse,
            linear_depth: &depth,
            skin: &skin,
        };
        let params = PoissonParams::from_profile();
        for levels in [1, 3] {
            let out = poisson(&input, &normals, &params, 20f32.to_radians(), 10.0, levels);
            assert_close(&out, &diffuse, 1e-3);
        }
    }

    #[test]
    fn poisson_ignores_samples_across_depth_steps() {
        // Left half red at depth 1, right half blue 20 mm behind (1 unit =
        // 10 mm, so the 3.5 mm disk spans ~16 px): the depth weight
        // (sensitivity ~0.04/mm^2) kills the cross-edge samples.
        let (w, h) = (32, 16);
        let mm_per_unit = 10.0;
        let mut diffuse = Vec::new();
        let mut depth = Vec::new();
        for _ in 0..h {
            for x in 0..w {
                let left = x < w / 2;
                diffuse.push(if left {
                    [1.0, 0.0, 0.0, 1.0]
                } else {
                    [0.0, 0.0, 1.0, 1.0]
                });
                depth.push(if left { 1.0 } else { 3.0 });
            }
        }
        let skin = vec![true; w * h];
        let run = |depth: &[f32]| {
            let input = MirrorInput {
                width: w,
                height: h,
                diffuse: &diffuse,
                linear_depth: depth,
                skin: &skin,
            };
            poisson(
                &input,
                &flat_normals(w * h),
                &PoissonParams::from_profile(),
                20f32.to_radians(),
                mm_per_unit,
                1,
            )
        };
        // First blue pixel of a middle row.
        let p = (h / 2) * w + w / 2;
        let step = run(&depth);
        // Control: at equal depth red does bleed in.
        let flat = run(&vec![3.0; w * h]);
        assert!(
            flat[p][0] > 0.05,
            "no bleeding at equal depth: {:?}",
            flat[p]
        );
        // Across the step only what a tap within a pixel of the step reads
        // through the bilinear filter (an interpolated depth and colour)
        // gets in: a few percent of the bleeding at equal depth.
        assert!(
            step[p][0] < 0.05 * flat[p][0],
            "red bled across the step: {:?} vs {:?}",
            step[p],
            flat[p]
        );
        println!(
            "across the step {:?}, at equal depth {:?}",
            step[p], flat[p]
        );
    }
}
