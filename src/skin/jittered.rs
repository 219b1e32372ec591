//! Hable et al.'s 13-tap jittered kernel, adapted to screen space (the
//! thesis' "SS Jittered" shader, Table 4.1).
//!
//! One 2D pass instead of a chain of separable Gaussians: a centre tap and
//! two rings of six taps each, rotated by a per-pixel angle so that the
//! ring structure turns into noise instead of visible copies (banding).
//!
//! # Derivation from the six-Gaussian fit (Table 4.2)
//!
//! * centre = Gaussians 1-2 (variances 0.0064 and 0.0484 mm^2, sigma <=
//!   0.22 mm): narrower than the rings, so they are treated as unblurred;
//! * mid ring = Gaussians 3-4 (0.187, 0.567 mm^2);
//! * wide ring = Gaussians 5-6 (1.99, 7.41 mm^2), red only as in Hable et
//!   al.: green and blue have (almost) no weight there, so their Gaussians
//!   5-6 weight is folded into the mid ring instead;
//! * per-channel weights are sums of `w_i`, so each channel still sums to 1;
//! * ring radius: the mean distance from the centre of a 2D Gaussian of
//!   per-axis variance `v` (a Rayleigh distribution) is `sqrt(pi v / 2)`;
//!   each ring takes the red-weight-weighted mean of that over its
//!   Gaussians (red is the channel the rings mostly serve).

use std::f32::consts::PI;

use super::profile::{SIX_GAUSSIAN_VARIANCES_MM2, SIX_GAUSSIAN_WEIGHTS_RGB};

/// Weights and radii of the 13-tap kernel.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct JitteredKernel {
    /// Weight of the centre tap per channel.
    pub center: [f32; 3],
    /// Total weight of the 6 mid-ring taps (each gets `mid / 6`).
    pub mid: [f32; 3],
    /// Total weight of the 6 wide-ring taps: red only, `g = b = 0`.
    pub wide: [f32; 3],
    /// Radius of the mid ring on the surface, mm.
    pub mid_radius_mm: f32,
    /// Radius of the wide ring on the surface, mm.
    pub wide_radius_mm: f32,
}

/// Mean radius of a 2D Gaussian with per-axis variance `v`: `sqrt(pi v/2)`.
fn mean_radius(v: f32) -> f32 {
    (PI * v / 2.0).sqrt()
}

/// Sum of `w_i` over the Gaussians `range` (0-based) for channel `c`.
fn weight_sum(range: std::ops::Range<usize>, c: usize) -> f32 {
    SIX_GAUSSIAN_WEIGHTS_RGB[range].iter().map(|w| w[c]).sum()
}

/// Red-weight-weighted mean radius over the Gaussians `range` (0-based).
fn ring_radius(range: std::ops::Range<usize>) -> f32 {
    let total = weight_sum(range.clone(), 0);
    range
        .map(|i| SIX_GAUSSIAN_WEIGHTS_RGB[i][0] * mean_radius(SIX_GAUSSIAN_VARIANCES_MM2[i]))
        .sum::<f32>()
        / total
}

/// The kernel derived from the six-Gaussian fit (see the module docs).
pub fn hable_kernel() -> JitteredKernel {
    let mut center = [0.0f32; 3];
    let mut mid = [0.0f32; 3];
    let mut wide = [0.0f32; 3];
    for c in 0..3 {
        center[c] = weight_sum(0..2, c);
        mid[c] = weight_sum(2..4, c);
        let outer = weight_sum(4..6, c);
        if c == 0 {
            wide[c] = outer;
        } else {
            mid[c] += outer;
        }
    }
    JitteredKernel {
        center,
        mid,
        wide,
        mid_radius_mm: ring_radius(2..4),
        wide_radius_mm: ring_radius(4..6),
    }
}

/// Per-pixel rotation of the rings, in `[0, PI/3)` (the rings repeat every
/// 60 degrees).
///
/// A cheap integer hash so the GPU (GLSL `uint` arithmetic, which wraps)
/// reproduces it bit for bit: `h = x*1973 + y*9277`;
/// `h = (h ^ (h >> 13)) * 0x5bd1e995`; `h ^= h >> 15`;
/// `angle = (h & 0xffff) / 65536 * (PI / 3)`, the last line in f32.
pub fn jitter_angle(x: u32, y: u32) -> f32 {
    (pixel_hash(x, y) & 0xffff) as f32 / 65536.0 * (PI / 3.0)
}

/// The integer hash of a pixel that turns the screen-space kernels per pixel
/// (ss-jittered's rings, the 2D gather's disk), as their shaders compute it.
pub fn pixel_hash(x: u32, y: u32) -> u32 {
    let mut h = x.wrapping_mul(1973).wrapping_add(y.wrapping_mul(9277));
    h = (h ^ (h >> 13)).wrapping_mul(0x5bd1_e995);
    h ^ (h >> 15)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kernel_weights_sum_to_one_per_channel() {
        let k = hable_kernel();
        for c in 0..3 {
            let s = k.center[c] + k.mid[c] + k.wide[c];
            assert!((s - 1.0).abs() < 1e-6, "channel {c}: {s}");
        }
        assert_eq!(k.wide[1], 0.0);
        assert_eq!(k.wide[2], 0.0);
    }

    #[test]
    fn kernel_values() {
        let k = hable_kernel();
        let close = |a: f32, b: f32| (a - b).abs() < 1e-5;
        assert!(close(k.center[0], 0.333) && close(k.center[1], 0.791));
        assert!(close(k.center[2], 0.993));
        assert!(close(k.mid[0], 0.231) && close(k.mid[1], 0.209));
        assert!(close(k.mid[2], 0.007));
        assert!(close(k.wide[0], 0.436));
        assert!((k.mid_radius_mm - 0.74).abs() < 0.01, "{}", k.mid_radius_mm);
        assert!(
            (k.wide_radius_mm - 2.06).abs() < 0.01,
            "{}",
            k.wide_radius_mm
        );
    }

    #[test]
    fn mean_radius_of_a_gaussian() {
        // Monte-Carlo-free check: integral of r * r exp(-r^2/2v)/v dr (the
        // Rayleigh density) by the midpoint rule.
        let v = 0.567f64;
        let n = 200_000;
        let h = 20.0 / n as f64;
        let mean: f64 = (0..n)
            .map(|i| {
                let r = (i as f64 + 0.5) * h;
                r * r / v * (-r * r / (2.0 * v)).exp() * h
            })
            .sum();
        assert!((mean as f32 - mean_radius(v as f32)).abs() < 1e-5);
    }

    #[test]
    fn jitter_angle_matches_the_hash() {
        // Hand-evaluated: (0,0) hashes to 0.
        assert_eq!(jitter_angle(0, 0), 0.0);
        // (1, 0): h = 1973; 1973 >> 13 = 0; 1973 * 0x5bd1e995 wraps.
        let mut h = 1973u32.wrapping_mul(0x5bd1_e995);
        h ^= h >> 15;
        assert_eq!(
            jitter_angle(1, 0),
            (h & 0xffff) as f32 / 65536.0 * (PI / 3.0)
        );
        // Huge coordinates wrap instead of overflowing.
        let a = jitter_angle(u32::MAX, u32::MAX);
        assert!((0.0..PI / 3.0).contains(&a));
        // Spread over the range, and different for neighbours.
        let angles: Vec<f32> = (0..64).map(|i| jitter_angle(i % 8, i / 8)).collect();
        let mean = angles.iter().sum::<f32>() / 64.0;
        assert!((mean - PI / 6.0).abs() < 0.15, "mean {mean}");
        assert_ne!(jitter_angle(3, 4), jitter_angle(4, 4));
        assert!(angles.iter().all(|a| (0.0..PI / 3.0).contains(a)));
    }
}
