//! CPU mirror of the two screen-space separable SSS passes.
//!
//! This mirrors the GPU shader operation by operation (f32 arithmetic,
//! Vulkan bilinear filtering with clamp-to-edge, RGBA16F intermediate
//! storage) so a test can compare the GPU image with it per pixel.
//!
//! Per pass, direction `d = (1, 0)` or `(0, 1)`, for each skin pixel:
//! * `colorM = src[p]`, `depthM = depth[p]`, `strength = colorM.a`;
//! * `uv = ((x + 0.5)/width, (y + 0.5)/height)`;
//! * screen height in scene units at that depth `H = 2 depthM tan(fovy/2)`;
//!   uv step per mm `su = d / mm_per_unit / H`, the horizontal component
//!   also divided by `aspect = width/height` (one mm has the same on-screen
//!   length in both directions);
//! * `out.rgb = w_0 colorM.rgb + sum_i w_i mix(c_i, colorM, s_i)` with
//!   `uv_i = uv + (offset_i * strength) * su`, `c_i`, `depth_i` bilinear at
//!   `uv_i`, and follow-surface factor
//!   `s_i = clamp(|depthM - depth_i| mm_per_unit / follow_tolerance_mm, 0, 1)`
//!   (0 when follow-surface is off or the tolerance is <= 0);
//! * `out.a = colorM.a`. Non-skin pixels of `dst` are not written.
//!
//! `mix(a, b, s)` and bilinear lerps are evaluated as `a + (b - a) * s`.
//! Note: real texture units quantise the bilinear fraction (typically 8
//! sub-texel bits), so GPU results can differ from this mirror by up to
//! ~1/512 of the difference between neighbouring texels.

use super::kernel::SeparableKernel;
use super::mirror::MirrorInput;

/// Camera and scale information the passes need.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SssView {
    /// Vertical field of view, radians.
    pub fovy_rad: f32,
    /// Millimetres per scene unit (converts kernel mm to scene units).
    pub mm_per_unit: f32,
    /// Lerp samples back to the centre colour across depth discontinuities.
    pub follow_surface: bool,
    /// Depth difference (mm) at which a sample is fully replaced.
    pub follow_tolerance_mm: f32,
}

use super::texel::{bilinear as bilinear_uv, lerp, round_f16};

/// Bilinear fetch of `C` channels at `uv` (the rule of `screen_mirror`).
fn bilinear<const C: usize>(
    tex: &[[f32; C]],
    width: usize,
    height: usize,
    uv: [f32; 2],
) -> [f32; C] {
    bilinear_uv(tex, width, height, uv[0], uv[1])
}

/// One separable pass (horizontal or vertical) from `input_color` into
/// `dst`; only skin pixels of `dst` are written.
///
/// Panics if a slice length differs from `width * height` (a caller bug,
/// not user input).
#[allow(clippy::too_many_arguments)] // mirrors the shader's inputs one-to-one
pub fn sss_pass(
    input_color: &[[f32; 4]],
    linear_depth: &[f32],
    skin: &[bool],
    width: usize,
    height: usize,
    kernel: &SeparableKernel,
    view: &SssView,
    horizontal: bool,
    dst: &mut [[f32; 4]],
) {
    let n = width * height;
    assert_eq!(input_color.len(), n, "input_color size");
    assert_eq!(linear_depth.len(), n, "linear_depth size");
    assert_eq!(skin.len(), n, "skin mask size");
    assert_eq!(dst.len(), n, "dst size");
    let Some((centre, others)) = kernel.samples.split_first() else {
        return;
    };
    // Depth as a 1-channel texture for the generic bilinear fetch.
    let depth_tex: Vec<[f32; 1]> = linear_depth.iter().map(|&d| [d]).collect();
    let follow = view.follow_surface && view.follow_tolerance_mm > 0.0;
    let aspect = width as f32 / height as f32;
    let scale = crate::view::ViewScale::new(height as u32, view.fovy_rad, view.mm_per_unit);
    let inv_mm_per_unit = 1.0 / view.mm_per_unit;

    for y in 0..height {
        for x in 0..width {
            let p = y * width + x;
            if !skin[p] {
                continue;
            }
            let color_m = input_color[p];
            let depth_m = linear_depth[p];
            let strength = color_m[3];
            let uv = [
                (x as f32 + 0.5) / width as f32,
                (y as f32 + 0.5) / height as f32,
            ];
            let screen_h = scale.screen_height_units(depth_m);
            let step_mm = inv_mm_per_unit / screen_h;
            let step = if horizontal {
                [step_mm / aspect, 0.0]
            } else {
                [0.0, step_mm]
            };

            let mut acc = [0.0f32; 3];
            for c in 0..3 {
                acc[c] = centre.weight[c] * color_m[c];
            }
            for s in others {
                let k = s.offset_mm * strength;
                let uv_i = [uv[0] + k * step[0], uv[1] + k * step[1]];
                let col = bilinear(input_color, width, height, uv_i);
                let mix = if follow {
                    let [d] = bilinear(&depth_tex, width, height, uv_i);
                    ((depth_m - d).abs() * view.mm_per_unit / view.follow_tolerance_mm)
                        .clamp(0.0, 1.0)
                } else {
                    0.0
                };
                for c in 0..3 {
                    acc[c] += s.weight[c] * lerp(col[c], color_m[c], mix);
                }
            }
            dst[p] = [acc[0], acc[1], acc[2], color_m[3]];
        }
    }
}

/// Both passes as the GPU runs them: the intermediate target starts as a
/// copy of the diffuse target, the horizontal pass writes its skin pixels,
/// it is stored as RGBA16F; the output starts as a copy of the diffuse
/// target, the vertical pass reads the intermediate, and the result is
/// stored as RGBA16F.
pub fn separable_sss(
    input: &MirrorInput,
    kernel: &SeparableKernel,
    view: &SssView,
) -> Vec<[f32; 4]> {
    let (w, h) = (input.width, input.height);
    let mut tmp = input.diffuse.to_vec();
    sss_pass(
        input.diffuse,
        input.linear_depth,
        input.skin,
        w,
        h,
        kernel,
        view,
        true,
        &mut tmp,
    );
    tmp.iter_mut().for_each(|t| *t = round_f16(*t));
    let mut out = input.diffuse.to_vec();
    sss_pass(
        &tmp,
        input.linear_depth,
        input.skin,
        w,
        h,
        kernel,
        view,
        false,
        &mut out,
    );
    out.iter_mut().for_each(|t| *t = round_f16(*t));
    out
}

#[cfg(test)]
mod tests {
    use super::super::kernel::{Preset, SssParams};
    use super::*;

    /// 1 unit = 10 mm and fovy 60 degrees: at depth 1 the screen is 11.5 mm
    /// tall, so on a 32-pixel-high image the 3.22 mm kernel spans ~9 pixels.
    fn view(follow: bool) -> SssView {
        SssView {
            fovy_rad: 60f32.to_radians(),
            mm_per_unit: 10.0,
            follow_surface: follow,
            follow_tolerance_mm: 0.01,
        }
    }

    fn kernel() -> SeparableKernel {
        SeparableKernel::build(Preset::Table61.params(), 17).unwrap()
    }

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

    #[test]
    fn zero_width_or_zero_strength_is_identity() {
        let (w, h) = (24, 16);
        let diffuse = noise_image(w * h, 1.0);
        let depth = vec![1.0; w * h];
        let skin = vec![true; w * h];
        let input = MirrorInput {
            width: w,
            height: h,
            diffuse: &diffuse,
            linear_depth: &depth,
            skin: &skin,
        };
        let base = Preset::Table61.params();
        for params in [
            SssParams {
                width_mm: 0.0,
                ..base
            },
            SssParams {
                strength: [0.0; 3],
                ..base
            },
        ] {
            let k = SeparableKernel::build(params, 17).unwrap();
            assert_eq!(separable_sss(&input, &k, &view(false)), diffuse);
        }
        // Per-pixel strength 0: all taps land on the centre texel.
        let flat = noise_image(w * h, 0.0);
        let input = MirrorInput {
            diffuse: &flat,
            ..input
        };
        let out = separable_sss(&input, &kernel(), &view(false));
        for (a, b) in out.iter().zip(&flat) {
            for c in 0..4 {
                assert!((a[c] - b[c]).abs() <= 1e-3 * b[c].abs().max(1e-3));
            }
        }
    }

    #[test]
    fn constant_image_stays_constant() {
        let (w, h) = (40, 32);
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
        for follow in [false, true] {
            let out = separable_sss(&input, &kernel(), &view(follow));
            for px in &out {
                for c in 0..4 {
                    assert!((px[c] - colour[c]).abs() <= 1e-3 * colour[c], "{px:?}");
                }
            }
        }
    }

    #[test]
    fn non_skin_pixels_are_untouched() {
        let (w, h) = (20, 18);
        let diffuse = noise_image(w * h, 1.0);
        let depth: Vec<f32> = (0..w * h).map(|i| 1.0 + (i % 7) as f32 * 0.01).collect();
        let skin: Vec<bool> = (0..w * h).map(|i| (i / 3) % 2 == 0).collect();
        // Single pass: non-skin texels of dst keep a sentinel value.
        let sentinel = [-7.0, 1e9, f32::MIN_POSITIVE, 3.5];
        let mut dst = vec![sentinel; w * h];
        sss_pass(
            &diffuse,
            &depth,
            &skin,
            w,
            h,
            &kernel(),
            &view(true),
            true,
            &mut dst,
        );
        for (i, px) in dst.iter().enumerate() {
            assert_eq!(*px == sentinel, !skin[i], "pixel {i}");
        }
        // Full effect on f16-representable input: bit-identical.
        let input = MirrorInput {
            width: w,
            height: h,
            diffuse: &diffuse,
            linear_depth: &depth,
            skin: &skin,
        };
        let out = separable_sss(&input, &kernel(), &view(false));
        let mut changed = 0;
        for i in 0..w * h {
            if skin[i] {
                changed += usize::from(out[i] != diffuse[i]);
            } else {
                let (a, b) = (out[i].map(f32::to_bits), diffuse[i].map(f32::to_bits));
                assert_eq!(a, b, "pixel {i}");
            }
        }
        assert!(changed > 0, "skin pixels were not blurred");
    }

    /// Red on the near left half (depth 1), blue on the far right (depth 2).
    fn step_scene(w: usize, h: usize) -> (Vec<[f32; 4]>, Vec<f32>) {
        let mut diffuse = Vec::with_capacity(w * h);
        let mut depth = Vec::with_capacity(w * h);
        for _ in 0..h {
            for x in 0..w {
                let left = x < w / 2;
                diffuse.push(if left {
                    [1.0, 0.0, 0.0, 1.0]
                } else {
                    [0.0, 0.0, 1.0, 1.0]
                });
                depth.push(if left { 1.0 } else { 2.0 });
            }
        }
        (diffuse, depth)
    }

    #[test]
    fn follow_surface_stops_bleeding_across_depth_steps() {
        let (w, h) = (48, 32);
        let (diffuse, depth) = step_scene(w, h);
        let skin = vec![true; w * h];
        let input = MirrorInput {
            width: w,
            height: h,
            diffuse: &diffuse,
            linear_depth: &depth,
            skin: &skin,
        };
        let off = separable_sss(&input, &kernel(), &view(false));
        let on = separable_sss(&input, &kernel(), &view(true));
        // First blue pixel of a middle row: the wide red kernel pulls red
        // across the edge unless follow-surface stops it.
        let p = (h / 2) * w + w / 2;
        assert!(off[p][0] > 0.05, "no bleeding without follow: {:?}", off[p]);
        assert!(on[p][0] < 1e-3, "bleeding with follow: {:?}", on[p]);
        // Tolerance <= 0 disables follow-surface.
        let disabled = SssView {
            follow_tolerance_mm: 0.0,
            ..view(true)
        };
        assert_eq!(separable_sss(&input, &kernel(), &disabled), off);
    }

    #[test]
    fn one_mm_has_the_same_pixel_length_in_both_directions() {
        // Non-square image: the horizontal step is divided by the aspect.
        let (w, h) = (64, 32);
        let mut diffuse = vec![[0.0, 0.0, 0.0, 1.0]; w * h];
        diffuse[(h / 2) * w + w / 2] = [1.0, 1.0, 1.0, 1.0];
        let depth = vec![1.0; w * h];
        let skin = vec![true; w * h];
        let k = kernel();
        let v = view(false);
        let mut hor = diffuse.clone();
        let mut ver = diffuse.clone();
        sss_pass(&diffuse, &depth, &skin, w, h, &k, &v, true, &mut hor);
        sss_pass(&diffuse, &depth, &skin, w, h, &k, &v, false, &mut ver);
        let row: Vec<f32> = (0..w).map(|x| hor[(h / 2) * w + x][0]).collect();
        let col: Vec<f32> = (0..h).map(|y| ver[y * w + w / 2][0]).collect();
        let lit = |v: &[f32]| v.iter().filter(|&&c| c > 0.0).count();
        assert!(lit(&row) > 3);
        assert_eq!(lit(&row), lit(&col));
        // Energy along each line matches as well.
        let (sr, sc): (f32, f32) = (row.iter().sum(), col.iter().sum());
        assert!((sr - sc).abs() < 1e-4, "{sr} vs {sc}");
    }

    #[test]
    fn round_f16_rounds() {
        let r = round_f16([1.0, 0.1, 65504.0, 1e-8]);
        assert_eq!(r[0], 1.0);
        assert!((r[1] - 0.1).abs() < 1e-4 && r[1] != 0.1);
        assert_eq!(r[2], 65504.0);
        assert_eq!(r[3], 0.0);
    }
}
