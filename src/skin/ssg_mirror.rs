//! CPU mirror of the whole screen-space sum-of-Gaussians chain
//! (thesis section 4.2.1, Figure 4.6 right), operation by operation as the
//! GPU runs it, so GPU and CPU images can be compared per pixel.
//!
//! Targets: `RT1` (widest Gaussian so far), `RT2` (ping-pong) and `RTF`
//! (final), all RGBA16F and all seeded with a copy of the diffuse image.
//! Per Gaussian `g` of [`ssg_gaussians`] with LOD quad depth `q`, a skin
//! pixel `p` is shaded in both passes iff `q > ndc_depth[p]` (the quad is
//! drawn at depth `q` with depth test GREATER; strict, f32 compare):
//!
//! * horizontal: `colorM = RT1[p]`, `s = s_x * colorM.a`,
//!   `step = s * sigma_g / 3` pixels, `out.rgb = sum_k W[k+3] *
//!   bilinear(RT1, uv + (k * step / width, 0)).rgb` for `k = -3..=3`
//!   (accumulated in that order from 0), `out.a = colorM.a`, `RT2[p] = f16(out)`;
//! * vertical: the same on `RT2` with `s_y` and `(0, k * step / height)`,
//!   result `r`; `RT1[p] = f16(r)` and, blending with the constant colour
//!   `w'_g` (alpha constant 1), `RTF[p] = f16(r.rgb * w' + RTF[p].rgb *
//!   (1 - w'), r.a)`.
//!
//! Reads and writes never alias (the horizontal pass reads RT1 and writes
//! RT2, the vertical one reads RT2 and writes RT1/RTF), so the in-place
//! updates below equal the GPU's. Pixels not shaded by a pass keep whatever
//! their target held, including stale values from earlier Gaussians, which
//! the next pass may sample: that is the GPU's behaviour too.

use super::mirror::MirrorInput;
use super::ssg::{ssg_gaussians, GaussianFit, Stretch, LISTING_4_1_WEIGHTS};
use super::texel::{bilinear4, pixel_uv, round_f16_with, F16Rounding};

/// Inputs of the chain: the frame every mirror reads, and the hardware depth
/// buffer (D32 float) the LOD quads are tested against.
#[derive(Clone, Copy, Debug)]
pub struct SsgInput<'a> {
    pub frame: MirrorInput<'a>,
    /// The hardware depth buffer, compared against the LOD quad depths.
    pub ndc_depth: &'a [f32],
}

/// Whether a pass of a Gaussian whose quad is drawn at depth `quad_depth`
/// shades pixel `p` (stencil skin, depth test GREATER).
pub fn shaded(input: &SsgInput, p: usize, quad_depth: f32) -> bool {
    input.frame.skin[p] && quad_depth > input.ndc_depth[p]
}

/// One 7-tap blur pass of `src` (Listing 4.1); `write(p, out)` receives the
/// unrounded result of every shaded pixel, so the caller decides which
/// targets it goes to and how it is blended and stored.
fn blur_pass(
    input: &SsgInput,
    stretch: &Stretch,
    std_mm: f32,
    quad_depth: f32,
    horizontal: bool,
    src: &[[f32; 4]],
    mut write: impl FnMut(usize, [f32; 4]),
) {
    let (w, h) = (input.frame.width, input.frame.height);
    for y in 0..h {
        for x in 0..w {
            let p = y * w + x;
            if !shaded(input, p, quad_depth) {
                continue;
            }
            let color_m = src[p];
            let [sx, sy] = stretch.factors(input.frame.linear_depth, w, h, x, y);
            let s = if horizontal { sx } else { sy } * color_m[3];
            let step_px = s * std_mm / 3.0;
            let [u, v] = pixel_uv(x, y, w, h);
            let mut acc = [0.0f32; 3];
            for (i, &wt) in LISTING_4_1_WEIGHTS.iter().enumerate() {
                let k = i as f32 - 3.0;
                let (us, vs) = if horizontal {
                    (u + k * step_px / w as f32, v)
                } else {
                    (u, v + k * step_px / h as f32)
                };
                let tap = bilinear4(src, w, h, us, vs);
                for c in 0..3 {
                    acc[c] += wt * tap[c];
                }
            }
            write(p, [acc[0], acc[1], acc[2], color_m[3]]);
        }
    }
}

/// The whole chain; returns `RTF`.
///
/// `quad_depths` holds one LOD quad depth per entry of
/// `ssg_gaussians(fit)` (1.0 disables LOD for a D32 buffer cleared to 1
/// with geometry < 1; 0.0 skips the Gaussian everywhere).
///
/// Panics if a slice length is wrong (a caller bug, not user input).
pub fn ssg(
    input: &SsgInput,
    fit: GaussianFit,
    stretch: Stretch,
    quad_depths: &[f32],
) -> Vec<[f32; 4]> {
    ssg_with_rounding(input, fit, stretch, quad_depths, F16Rounding::NearestEven)
}

/// `ssg` with the device's f16 store rounding (see [`F16Rounding`]).
pub fn ssg_with_rounding(
    input: &SsgInput,
    fit: GaussianFit,
    stretch: Stretch,
    quad_depths: &[f32],
    rounding: F16Rounding,
) -> Vec<[f32; 4]> {
    input.frame.check();
    let n = input.frame.width * input.frame.height;
    assert_eq!(input.ndc_depth.len(), n, "ndc_depth size");
    let gaussians = ssg_gaussians(fit);
    assert_eq!(
        quad_depths.len(),
        gaussians.len(),
        "one quad depth per Gaussian"
    );

    let mut rt1 = input.frame.diffuse.to_vec();
    let mut rt2 = input.frame.diffuse.to_vec();
    let mut rtf = input.frame.diffuse.to_vec();
    for (g, &q) in gaussians.iter().zip(quad_depths) {
        blur_pass(
            input,
            &stretch,
            g.incremental_std_mm,
            q,
            true,
            &rt1,
            |p, o| {
                rt2[p] = round_f16_with(o, rounding);
            },
        );
        let wp = g.blend;
        blur_pass(
            input,
            &stretch,
            g.incremental_std_mm,
            q,
            false,
            &rt2,
            |p, r| {
                rt1[p] = round_f16_with(r, rounding);
                let d = rtf[p];
                let mut b = [0.0f32; 4];
                for c in 0..3 {
                    b[c] = r[c] * wp[c] + d[c] * (1.0 - wp[c]);
                }
                b[3] = r[3];
                rtf[p] = round_f16_with(b, rounding);
            },
        );
    }
    rtf
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::skin::texel::round_f16;

    fn noise_image(n: usize, alpha: f32) -> Vec<[f32; 4]> {
        let mut state = 0x1234_5678_u32;
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

    struct Scene {
        w: usize,
        h: usize,
        diffuse: Vec<[f32; 4]>,
        depth: Vec<f32>,
        skin: Vec<bool>,
        ndc: Vec<f32>,
    }

    impl Scene {
        fn new(w: usize, h: usize, alpha: f32, all_skin: bool) -> Scene {
            let n = w * h;
            Scene {
                w,
                h,
                diffuse: noise_image(n, alpha),
                depth: (0..n).map(|i| 1.0 + (i % 3) as f32 * 0.0002).collect(),
                skin: (0..n).map(|i| all_skin || (i / 5) % 3 != 1).collect(),
                // A ramp of hardware depths across the image.
                ndc: (0..n)
                    .map(|i| 0.5 + 0.4 * (i % w) as f32 / w as f32)
                    .collect(),
            }
        }

        fn input(&self) -> SsgInput<'_> {
            SsgInput {
                frame: MirrorInput {
                    width: self.w,
                    height: self.h,
                    diffuse: &self.diffuse,
                    linear_depth: &self.depth,
                    skin: &self.skin,
                },
                ndc_depth: &self.ndc,
            }
        }
    }

    fn no_lod(fit: GaussianFit) -> Vec<f32> {
        vec![1.0; ssg_gaussians(fit).len()]
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

    #[test]
    fn zero_strength_is_identity_up_to_rounding() {
        let s = Scene::new(20, 14, 0.0, true);
        for fit in GaussianFit::ALL {
            let out = ssg(&s.input(), fit, Stretch::THESIS, &no_lod(fit));
            // All taps on the centre texel; only the weight sum and the
            // blend of identical values can move the last f16 bit.
            assert_close(&out, &s.diffuse, 2e-3);
        }
    }

    #[test]
    fn constant_image_stays_constant() {
        let colour = round_f16([0.8, 0.45, 0.3, 1.0]);
        let mut s = Scene::new(24, 16, 1.0, true);
        s.diffuse = vec![colour; 24 * 16];
        for fit in GaussianFit::ALL {
            let out = ssg(&s.input(), fit, Stretch::THESIS, &no_lod(fit));
            assert_close(&out, &s.diffuse, 2e-3);
        }
    }

    #[test]
    fn non_skin_untouched_and_skin_blurred() {
        let s = Scene::new(30, 20, 1.0, false);
        let out = ssg(
            &s.input(),
            GaussianFit::Six,
            Stretch::THESIS,
            &no_lod(GaussianFit::Six),
        );
        let mut changed = 0;
        for (i, o) in out.iter().enumerate() {
            if s.skin[i] {
                changed += usize::from(*o != s.diffuse[i]);
                assert_eq!(o[3], s.diffuse[i][3]);
                assert_eq!(*o, round_f16(*o));
            } else {
                assert_eq!(
                    o.map(f32::to_bits),
                    s.diffuse[i].map(f32::to_bits),
                    "pixel {i}"
                );
            }
        }
        assert!(changed > s.w * s.h / 2, "only {changed} changed");
    }

    #[test]
    fn everything_skipped_is_exact_identity() {
        let s = Scene::new(16, 12, 1.0, true);
        for fit in GaussianFit::ALL {
            let q = vec![0.0; ssg_gaussians(fit).len()];
            let out = ssg(&s.input(), fit, Stretch::THESIS, &q);
            assert_eq!(out, s.diffuse);
        }
    }

    #[test]
    fn lod_shades_exactly_the_pixels_in_front_of_the_quad() {
        // Only the widest 4-Gaussian step runs (w' red = 0.46), with its quad
        // in the middle of the ndc ramp.
        let s = Scene::new(32, 10, 1.0, false);
        let q_mid = s.ndc[16];
        let quads = [0.0, 0.0, q_mid];
        let out = ssg(&s.input(), GaussianFit::Four, Stretch::THESIS, &quads);
        let mut shaded_count = 0;
        for (p, o) in out.iter().enumerate() {
            if shaded(&s.input(), p, q_mid) {
                shaded_count += 1;
                assert_ne!(o[0], s.diffuse[p][0], "pixel {p} not shaded");
            } else {
                assert_eq!(*o, s.diffuse[p], "pixel {p} shaded");
            }
        }
        assert!(shaded_count > 0);
        // Pixels exactly at the quad depth fail the strict test.
        assert!(!shaded(&s.input(), 16, q_mid));
        assert!(shaded(&s.input(), 15, q_mid) == s.skin[15]);
    }

    #[test]
    fn wider_fits_blur_further() {
        // A single white skin pixel on black skin: the red energy spreads
        // out, alpha stays put, and the total stays ~1 (normalised blend).
        let (w, h) = (41, 41);
        let mut s = Scene::new(w, h, 1.0, true);
        s.diffuse = vec![[0.0, 0.0, 0.0, 1.0]; w * h];
        let c = (h / 2) * w + w / 2;
        s.diffuse[c] = [1.0, 1.0, 1.0, 1.0];
        s.depth = vec![1.0; w * h];
        // alpha 3 at depth 1: one mm of sigma is one pixel, so even the
        // widest step's taps (+-7 px) stay inside the image.
        let stretch = Stretch {
            alpha: 3.0,
            ..Stretch::THESIS
        };
        let out = ssg(
            &s.input(),
            GaussianFit::Six,
            stretch,
            &no_lod(GaussianFit::Six),
        );
        for ch in 0..3 {
            let total: f32 = out.iter().map(|p| p[ch]).sum();
            assert!((total - 1.0).abs() < 0.02, "channel {ch}: {total}");
        }
        // Red keeps less at the centre than blue (blue is mostly Gaussian 1-2).
        assert!(out[c][0] < out[c][2]);
    }
}
