//! Image error measures for comparing an SSS method's frame with the ground truth.
//!
//! Two complementary measures, because each misses what the other sees:
//! - relative RMSE on *linear* radiance measures physical accuracy (energy moved
//!   to the wrong place), independent of the tone mapper;
//! - FLIP on the *tone-mapped sRGB* frame measures what a viewer notices (banding,
//!   ringing, noise), which a mean-squared measure weighs poorly.
//!
//! Images are row-major `[f32; 4]` linear RGBA, top row first; alpha is ignored
//! everywhere because it carries SSS strength, not colour. A mask selects the
//! skin pixels so that the background, identical in every method, does not dilute
//! the error.

use anyhow::{bail, ensure, Context, Result};

/// Result of an LDR FLIP comparison.
#[derive(Clone, Debug)]
pub struct FlipResult {
    /// Mean of `error_map`: the single number the FLIP authors recommend reporting.
    pub mean: f64,
    /// Per-pixel FLIP error in 0..1, row-major, top row first.
    pub error_map: Vec<f32>,
}

/// Energy-normalised relative RMSE over the masked pixels' RGB channels:
///
/// `sqrt( sum (t - r)^2 / sum r^2 )`, both sums over masked pixels and R, G, B.
///
/// Normalising by the reference's energy rather than per pixel keeps dark pixels
/// (where a per-pixel ratio explodes) from dominating, and makes the value read as
/// "error relative to signal": a test uniformly 10% brighter than the reference
/// gives 0.1.
///
/// Errors when the three slices differ in length, when the mask selects no
/// pixel, when the reference is black over the mask (the measure is undefined),
/// or when a value is not finite.
pub fn relative_rmse(test: &[[f32; 4]], reference: &[[f32; 4]], mask: &[bool]) -> Result<f64> {
    ensure!(
        test.len() == reference.len(),
        "relative RMSE: test has {} pixels, reference {}",
        test.len(),
        reference.len()
    );
    ensure!(
        mask.len() == reference.len(),
        "relative RMSE: mask has {} entries, images {} pixels",
        mask.len(),
        reference.len()
    );
    let mut diff2 = 0.0f64;
    let mut ref2 = 0.0f64;
    let mut count = 0usize;
    for ((t, r), _) in test
        .iter()
        .zip(reference)
        .zip(mask)
        .filter(|(_, &inside)| inside)
    {
        count += 1;
        for c in 0..3 {
            let (tc, rc) = (f64::from(t[c]), f64::from(r[c]));
            diff2 += (tc - rc) * (tc - rc);
            ref2 += rc * rc;
        }
    }
    ensure!(count > 0, "relative RMSE: the mask selects no pixel");
    ensure!(
        diff2.is_finite() && ref2.is_finite(),
        "relative RMSE: an image holds a non-finite value inside the mask"
    );
    if ref2 == 0.0 {
        bail!("relative RMSE: the reference is black over all {count} masked pixels");
    }
    Ok((diff2 / ref2).sqrt())
}

/// LDR FLIP between two sRGB-encoded RGBA8 frames (alpha dropped), at FLIP's
/// default 67 pixels per degree (a 0.7 m wide, 3840-pixel monitor seen from 0.7 m).
///
/// Why the tone-mapped frame: FLIP models the human visual system on display
/// values, so it must see what the display shows, not linear radiance.
pub fn flip_ldr(
    test_srgb8: &[u8],
    reference_srgb8: &[u8],
    width: u32,
    height: u32,
) -> Result<FlipResult> {
    ensure!(
        width > 0 && height > 0,
        "FLIP: empty image ({width}x{height})"
    );
    // nv-flip computes `width * height * 3` in u32 and asserts on it: keep it in range.
    let pixels = u64::from(width) * u64::from(height); // cannot overflow: both < 2^32
    ensure!(
        pixels
            .checked_mul(3)
            .is_some_and(|b| b <= u64::from(u32::MAX)),
        "FLIP: image {width}x{height} is too large"
    );
    let expected = usize::try_from(pixels * 4).context("FLIP: image too large for memory")?;
    ensure!(
        test_srgb8.len() == expected,
        "FLIP: test image has {} bytes, {width}x{height} RGBA8 needs {expected}",
        test_srgb8.len()
    );
    ensure!(
        reference_srgb8.len() == expected,
        "FLIP: reference image has {} bytes, {width}x{height} RGBA8 needs {expected}",
        reference_srgb8.len()
    );
    let reference = nv_flip::FlipImageRgb8::with_data(width, height, &rgba_to_rgb(reference_srgb8));
    let test = nv_flip::FlipImageRgb8::with_data(width, height, &rgba_to_rgb(test_srgb8));
    let error_map = nv_flip::flip(reference, test, nv_flip::DEFAULT_PIXELS_PER_DEGREE).to_vec();
    // Accumulate in f64: a 4K frame's sum in f32 loses the small errors we compare.
    let mean = error_map.iter().map(|&e| f64::from(e)).sum::<f64>() / error_map.len() as f64;
    Ok(FlipResult { mean, error_map })
}

fn rgba_to_rgb(rgba: &[u8]) -> Vec<u8> {
    rgba.chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect()
}

/// Per-pixel mean absolute RGB error relative to the reference pixel's mean RGB:
/// `sum_c |t_c - r_c| / sum_c r_c` (the 1/3 factors cancel); 0 outside the mask.
///
/// Relative per pixel (unlike `relative_rmse`) because the map is for *looking*:
/// a halo in a dim region must show as brightly as one on a lit cheek. A reference
/// pixel darker than 1e-4 divides by 1e-4 instead, so black pixels that stay black
/// read 0 and black pixels that gain light read large, never infinite.
///
/// The map has one value per reference pixel; a pixel without a mask entry or a
/// test pixel counts as outside the mask (this never panics on mismatched
/// lengths; `relative_rmse` is the call that rejects them).
pub fn abs_error_map(test: &[[f32; 4]], reference: &[[f32; 4]], mask: &[bool]) -> Vec<f32> {
    const MIN_MEAN: f32 = 1e-4;
    reference
        .iter()
        .enumerate()
        .map(|(i, r)| match (test.get(i), mask.get(i)) {
            (Some(t), Some(true)) => {
                let abs = (0..3).map(|c| (t[c] - r[c]).abs()).sum::<f32>() / 3.0;
                let mean = (r[0] + r[1] + r[2]) / 3.0;
                abs / mean.max(MIN_MEAN)
            }
            _ => 0.0,
        })
        .collect()
}

/// Magma-like ramp stops (sRGB), from matplotlib's perceptually uniform 'magma':
/// black through purple and orange to pale yellow. Chosen over a rainbow because
/// its luminance rises monotonically, so brighter always means more error, also
/// when printed in grey.
const RAMP: [[u8; 3]; 9] = [
    [0x00, 0x00, 0x04],
    [0x1d, 0x11, 0x47],
    [0x51, 0x12, 0x7c],
    [0x82, 0x26, 0x81],
    [0xb6, 0x36, 0x79],
    [0xe6, 0x51, 0x64],
    [0xfb, 0x88, 0x61],
    [0xfe, 0xc2, 0x87],
    [0xfc, 0xfd, 0xbf],
];

/// RGBA8 heat map (opaque, magma-like ramp) of a per-pixel error, clamped to
/// `[0, max]` and quantised to 256 levels: 0 is near-black, `max` and above pale
/// yellow.
///
/// A fixed `max` rather than the image's own maximum lets maps of different
/// methods be compared side by side. NaN errors draw as `max`, so a broken pixel
/// is seen rather than hidden; a non-positive or non-finite `max` draws every
/// positive error as `max`. The output always holds `width * height` pixels;
/// missing error values draw as 0 and extra ones are ignored.
pub fn false_colour(error: &[f32], width: u32, height: u32, max: f32) -> Vec<u8> {
    let pixels = width as usize * height as usize;
    let mut out = Vec::with_capacity(pixels * 4);
    for i in 0..pixels {
        let e = error.get(i).copied().unwrap_or(0.0);
        let t = if e.is_nan() {
            1.0
        } else if !(max > 0.0 && max.is_finite()) {
            if e > 0.0 {
                1.0
            } else {
                0.0
            }
        } else {
            (e / max).clamp(0.0, 1.0)
        };
        // 256 levels, like any 8-bit colour map: finer steps would let 8-bit
        // rounding of magma's falling blue undo the rise in luminance.
        let [r, g, b] = ramp((t * 255.0).round() / 255.0);
        out.extend_from_slice(&[r, g, b, 255]);
    }
    out
}

/// The ramp at `t` in [0, 1], interpolated linearly between stops.
fn ramp(t: f32) -> [u8; 3] {
    let segments = (RAMP.len() - 1) as f32;
    let x = t.clamp(0.0, 1.0) * segments;
    let i = (x.floor() as usize).min(RAMP.len() - 2);
    let f = x - i as f32;
    let (a, b) = (RAMP[i], RAMP[i + 1]);
    std::array::from_fn(|c| {
        (f32::from(a[c]) + (f32::from(b[c]) - f32::from(a[c])) * f).round() as u8
    })
}

/// Sum of R, G and B over the masked pixels, in f64.
///
/// Why: SSS must move light, not create or destroy it; comparing the energy of
/// skin (and of the background next to it) before and after a pass exposes
/// halos and leaks that a per-pixel error spreads too thin to see. Pixels
/// without a mask entry count as outside the mask.
pub fn energy(img: &[[f32; 4]], mask: &[bool]) -> [f64; 3] {
    let mut sum = [0.0f64; 3];
    for (p, _) in img.iter().zip(mask).filter(|(_, &inside)| inside) {
        for c in 0..3 {
            sum[c] += f64::from(p[c]);
        }
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;

    fn uniform(n: usize, v: f32) -> Vec<[f32; 4]> {
        vec![[v, v, v, 1.0]; n]
    }

    #[test]
    fn rmse_identical_is_zero() {
        let img: Vec<[f32; 4]> = (0..16).map(|i| [i as f32, 0.5, 0.25, 1.0]).collect();
        let mask = vec![true; 16];
        assert_eq!(relative_rmse(&img, &img, &mask).unwrap(), 0.0);
    }

    #[test]
    fn rmse_ten_percent_brighter_is_point_one() {
        let mask = vec![true; 8];
        let e = relative_rmse(&uniform(8, 1.1), &uniform(8, 1.0), &mask).unwrap();
        assert!((e - 0.1).abs() < 1e-6, "{e}");
    }

    #[test]
    fn rmse_ignores_pixels_outside_mask_and_alpha() {
        let reference = uniform(4, 1.0);
        let mut test = uniform(4, 1.0);
        test[1] = [100.0, -5.0, 7.0, 1.0]; // outside the mask: must not count
        test[2][3] = 42.0; // alpha inside the mask: must not count
        test[3][0] = 2.0; // inside: one channel off by 1
        let mask = [true, false, true, true];
        let e = relative_rmse(&test, &reference, &mask).unwrap();
        // sum diff^2 = 1, sum ref^2 = 3 pixels * 3 channels = 9.
        assert!((e - (1.0f64 / 9.0).sqrt()).abs() < 1e-9, "{e}");
    }

    #[test]
    fn rmse_rejects_bad_input() {
        let a = uniform(4, 1.0);
        assert!(relative_rmse(&a, &uniform(3, 1.0), &[true; 4]).is_err());
        assert!(relative_rmse(&a, &a, &[true; 3]).is_err());
        assert!(relative_rmse(&a, &a, &[false; 4]).is_err());
        assert!(relative_rmse(&a, &uniform(4, 0.0), &[true; 4]).is_err());
        assert!(relative_rmse(&uniform(4, f32::NAN), &a, &[true; 4]).is_err());
    }

    fn rgba8(w: u32, h: u32, f: impl Fn(u32, u32) -> [u8; 4]) -> Vec<u8> {
        (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .flat_map(|(x, y)| f(x, y))
            .collect()
    }

    #[test]
    fn flip_identical_is_zero() {
        let img = rgba8(32, 24, |x, y| [(x * 8) as u8, (y * 10) as u8, 128, 255]);
        let r = flip_ldr(&img, &img, 32, 24).unwrap();
        assert_eq!(r.error_map.len(), 32 * 24);
        assert!(r.mean.abs() < 1e-6, "{}", r.mean);
    }

    #[test]
    fn flip_black_vs_white_is_large_and_alpha_is_ignored() {
        let black = rgba8(32, 32, |_, _| [0, 0, 0, 255]);
        let white = rgba8(32, 32, |_, _| [255, 255, 255, 0]);
        let r = flip_ldr(&black, &white, 32, 32).unwrap();
        assert!(r.mean > 0.5, "{}", r.mean);
        assert!(r.error_map.iter().all(|e| (0.0..=1.0).contains(e)));
        let white_opaque = rgba8(32, 32, |_, _| [255, 255, 255, 255]);
        let r2 = flip_ldr(&black, &white_opaque, 32, 32).unwrap();
        assert!((r.mean - r2.mean).abs() < 1e-9);
    }

    #[test]
    fn flip_small_change_is_small() {
        let a = rgba8(32, 32, |_, _| [120, 90, 80, 255]);
        let b = rgba8(32, 32, |_, _| [122, 90, 80, 255]);
        let black = rgba8(32, 32, |_, _| [0, 0, 0, 255]);
        let small = flip_ldr(&a, &b, 32, 32).unwrap().mean;
        let large = flip_ldr(&a, &black, 32, 32).unwrap().mean;
        assert!(small < 0.1 && small < large, "{small} vs {large}");
    }

    #[test]
    fn flip_rejects_bad_sizes() {
        let img = vec![0u8; 4 * 4 * 4];
        assert!(flip_ldr(&img, &img, 4, 3).is_err());
        assert!(flip_ldr(&img[..60], &img, 4, 4).is_err());
        assert!(flip_ldr(&img, &img[..60], 4, 4).is_err());
        assert!(flip_ldr(&[], &[], 0, 0).is_err());
        assert!(flip_ldr(&img, &img, u32::MAX, u32::MAX).is_err());
    }

    /// Relative luminance (Rec. 709) of an sRGB-encoded colour.
    fn luminance(rgb: [u8; 3]) -> f64 {
        let lin = |v: u8| {
            let c = f64::from(v) / 255.0;
            if c <= 0.04045 {
                c / 12.92
            } else {
                ((c + 0.055) / 1.055).powf(2.4)
            }
        };
        0.2126 * lin(rgb[0]) + 0.7152 * lin(rgb[1]) + 0.0722 * lin(rgb[2])
    }

    #[test]
    fn false_colour_endpoints_clamping_and_monotonic_luminance() {
        let n = 1001u32;
        let err: Vec<f32> = (0..n).map(|i| i as f32 / (n - 1) as f32 * 2.0).collect();
        let img = false_colour(&err, n, 1, 2.0);
        assert_eq!(img.len(), n as usize * 4);
        assert_eq!(&img[..4], &[0, 0, 4, 255]);
        assert_eq!(&img[img.len() - 4..], &[0xfc, 0xfd, 0xbf, 255]);
        let lum: Vec<f64> = img
            .chunks_exact(4)
            .map(|p| luminance([p[0], p[1], p[2]]))
            .collect();
        for w in lum.windows(2) {
            assert!(w[1] >= w[0], "luminance falls: {} -> {}", w[0], w[1]);
        }
        assert!(lum[lum.len() - 1] > 0.8 && lum[0] < 0.01);
        // Clamping: below 0 is the low end, above max (and NaN) the high end.
        let c = false_colour(&[-1.0, 5.0, f32::NAN], 3, 1, 2.0);
        assert_eq!(&c[..4], &img[..4]);
        assert_eq!(&c[4..8], &img[img.len() - 4..]);
        assert_eq!(&c[8..12], &img[img.len() - 4..]);
    }

    #[test]
    fn false_colour_handles_short_input_and_bad_max() {
        let c = false_colour(&[1.0], 2, 2, 1.0);
        assert_eq!(c.len(), 16);
        assert_eq!(&c[4..8], &[0, 0, 4, 255]);
        let z = false_colour(&[0.0, 0.3], 2, 1, 0.0);
        assert_eq!(&z[..4], &[0, 0, 4, 255]);
        assert_eq!(&z[4..8], &[0xfc, 0xfd, 0xbf, 255]);
    }

    #[test]
    fn abs_error_map_is_relative_and_masked() {
        let reference = vec![
            [1.0, 1.0, 1.0, 1.0],
            [0.1, 0.1, 0.1, 1.0],
            [1.0; 4],
            [0.0; 4],
        ];
        let test = vec![
            [1.5, 1.0, 1.0, 1.0],
            [0.2, 0.1, 0.1, 9.0],
            [9.0; 4],
            [0.0; 4],
        ];
        let mask = [true, true, false, true];
        let m = abs_error_map(&test, &reference, &mask);
        assert_eq!(m.len(), 4);
        assert!((m[0] - 0.5 / 3.0).abs() < 1e-6, "{}", m[0]);
        assert!((m[1] - 1.0 / 3.0).abs() < 1e-5, "{}", m[1]);
        assert_eq!(m[2], 0.0);
        assert_eq!(m[3], 0.0);
        // Mismatched lengths never panic; missing entries read as outside the mask.
        let short = abs_error_map(&test[..1], &reference, &mask[..2]);
        assert_eq!(short.len(), 4);
        assert!(short[0] > 0.0 && short[1] == 0.0);
    }

    #[test]
    fn energy_sums_masked_rgb() {
        let img = vec![[1.0, 2.0, 3.0, 100.0], [10.0, 20.0, 30.0, 1.0], [0.5; 4]];
        assert_eq!(energy(&img, &[true, false, true]), [1.5, 2.5, 3.5]);
        assert_eq!(energy(&img, &[false; 3]), [0.0; 3]);
        assert_eq!(energy(&img, &[true]), [1.0, 2.0, 3.0]);
    }
}
