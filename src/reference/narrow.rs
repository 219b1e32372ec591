//! The narrow part of the ground truth: Gaussians 1-3 of the six-Gaussian profile
//! (sigma 0.08, 0.22 and 0.43 mm) integrated over the visible skin surface.
//!
//! They hold 99% of green's and blue's weight and span 1-4 pixels of a 720p
//! close-up, so taking them as w_i L(x_o) at the pixel (as the ground truth once
//! did) leaves green and blue almost unscattered. Sampling them with the wide
//! part's surface samples would need a spacing under their sigma (hundreds of
//! samples per mm^2). Instead, a pass renders the skin at `s` x the frame's
//! resolution (each subsample: diffuse radiance, world position, normal, and
//! the surface area it covers), and each skin pixel sums, per Gaussian,
//!   M_i(x_o) = sum_q L_q G_i(|x_q - x_o|) A_q / sum_q G_i(|x_q - x_o|) A_q
//! over the subsamples within 4 sigma_3 that light can reach through tissue
//! (`tissue.rs`). Dividing by the sum of the weights makes each Gaussian exactly
//! energy-preserving however coarsely it is sampled (uniform light in, the same
//! light out), and fills what the visible surface lacks at a silhouette with
//! what it has, instead of losing it. M = sum_i w_i M_i joins the wide part.

use super::sampling::NARROW_GAUSSIANS;
use crate::skin::profile::SIX_GAUSSIAN_VARIANCES_MM2;

/// Largest supersampling factor per axis (memory: 9 subsamples of 36 bytes a pixel).
pub const MAX_SUPERSAMPLING: u32 = 3;
/// Subsamples per sigma of Gaussian 2 the factor aims for (two samples per
/// sigma keep a Gaussian's sampled sum within 1e-4 of its integral).
const SAMPLES_PER_SIGMA: f32 = 2.0;
/// Largest window radius (subsamples) a pixel's sum reaches: 4 sigma_3 at 30
/// pixels per mm (a 10x close-up), beyond which the sum would cost more than
/// the wide gather.
pub const MAX_RADIUS: u32 = 48;

/// Standard deviation (mm) of narrow Gaussian `i`.
pub fn sigma_mm(i: usize) -> f32 {
    SIX_GAUSSIAN_VARIANCES_MM2[i].sqrt()
}

/// The supersampling factor for a view whose nearest skin is `px_per_mm`
/// pixels per millimetre on screen: enough subsamples per sigma of Gaussian 2
/// (Gaussian 1 holds little of the light moved: w_1 sigma_1 is 12-18% of green's
/// and blue's moved energy), at most [`MAX_SUPERSAMPLING`].
pub fn supersampling(px_per_mm: f32) -> u32 {
    // NaN and non-positive scales (no skin in view) need no supersampling.
    if px_per_mm.is_nan() || px_per_mm <= 0.0 {
        return 1;
    }
    let need = SAMPLES_PER_SIGMA / (px_per_mm * sigma_mm(1));
    (need.ceil() as u32).clamp(1, MAX_SUPERSAMPLING)
}

/// Window radius in subsamples of a pixel at `px_per_mm` (at its depth) with
/// supersampling `s`: 4 sigma of the widest narrow Gaussian. Computed in f32
/// exactly as reference_narrow.comp does.
pub fn radius(px_per_mm: f32, s: u32) -> u32 {
    let r = (4.0 * sigma_mm(NARROW_GAUSSIANS - 1) * px_per_mm * s as f32).ceil();
    (r.max(1.0) as u32).min(MAX_RADIUS)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn supersampling_resolves_gaussian_two_up_to_its_cap() {
        // 720p close-up of the head (8.5 px/mm): sigma_2 is 1.9 px, 2 per sigma.
        assert_eq!(supersampling(8.5), 2);
        assert_eq!(supersampling(30.0), 1);
        assert_eq!(supersampling(1.5), MAX_SUPERSAMPLING);
        assert_eq!(supersampling(f32::NAN), 1);
        // The window covers 4 sigma_3 (0.43 mm), capped.
        assert_eq!(radius(8.5, 2), (4.0 * 0.4324 * 17.0f32).ceil() as u32);
        assert_eq!(radius(1000.0, 3), MAX_RADIUS);
        assert_eq!(NARROW_GAUSSIANS, 3);
    }
}
