//! The ground truth of Burley's normalized diffusion (`skin::burley`, matched
//! to the six-Gaussian skin by [`crate::skin::kernel::burley_profile`]): the
//! same two passes as the six Gaussians, split by distance instead of by
//! Gaussian.
//!
//! # The split
//!
//! `R(r) = A s (e^(-s r) + e^(-s r / 3)) / (8 pi r)` has no Gaussians to hand
//! out, so the profile is cut at a radius `r_c` ([`BURLEY_NEAR_MM`], 1 mm):
//! - **near** (`r < r_c`, `A F(r_c)` of the light: 62% of red's, 98% of
//!   green's, 99.5% of blue's) in the supersampled screen pass
//!   (`reference_burley_narrow.comp`), over the visible skin through tissue
//!   like Gaussians 1-3;
//! - **far** (`r >= r_c`, `A (1 - F(r_c))`) in the surface gather
//!   (`reference_burley_gather.comp`) with `R(r) dA_j`, out to the same
//!   cut-off as the six Gaussians (10.9 mm, where red's tail `1 - F` is 2e-4).
//!
//! Each part is normalised by its sampled weight sum per channel, as each
//! Gaussian is (`super::narrow` says why): uniform light in gives the same light
//! out, however coarsely a part is sampled. 1 mm because blue's mean radius
//! is 0.17 mm (s = 15/mm) and red's 1.1 mm: the near part must resolve the
//! first (the supersampled surface does, at 2-3 subsamples a pixel) and the far
//! part's samples (0.18 mm apart at the default density) must be fine beside
//! `r_c` (the midpoint rule on `1/r` at 1 mm errs by under 1%, then
//! normalised). It also keeps the near window small: 17 subsamples at the 720p
//! close-up (the six Gaussians' window is 4 sigma_3 = 1.7 mm).
//!
//! # The singularity
//!
//! `R` goes as `1/r` at 0. It integrates (the ring integral is the CDF), but a
//! subsample weighted by `R` at its centre is not its cell's integral near the
//! pixel's point: the four cells around the point of a 2x supersampled pixel
//! hold 2.5x what the ring estimate gives, and blue's whole profile is a
//! pixel wide. So each subsample within [`BURLEY_CELL_REACH`] cells of the
//! point (per axis) is weighted by the integral of `R` over its cell, the cell
//! taken as a square of side `h = sqrt(A_q)` at its offset on the subsample
//! grid (exact on a card facing the camera; near the point the surface is its
//! tangent plane): `R = (s / 4 pi) g(r) / r` with `g = (e^(-s r) + e^(-s r /
//! 3)) / 2` smooth, the cell cut into 4x4 parts, each `g` at its centre times
//! the exact integral of `1/r` over it ([`rect_inv_r`]). Farther subsamples
//! take the ring integral of `R` over their radial extent at their true 3D
//! distance, times their share of the ring ([`ring_weight`]; `R(r) A_q` alone
//! falls short by `(s h)^2 / 24`, 3% of blue's at the 720p close-up).
//!
//! The f64 mirror of both passes is `super::mirror::gather_f64_burley`.

use std::f64::consts::PI;

pub use crate::shader_constants::{BURLEY_CELL_REACH, BURLEY_NEAR_MM};
use crate::skin::burley::{radial_cdf, radial_tail};

use super::narrow::MAX_RADIUS;

/// Parts per axis a near cell is cut into (shared with
/// reference_burley.glsl through `crate::shader_constants`).
pub use crate::shader_constants::BURLEY_CELL_PARTS as CELL_PARTS;

/// Burley's scaling factor `s` per channel (1/mm).
pub fn s_per_mm() -> [f64; 3] {
    crate::shader_constants::burley_s_albedo().0
}

/// Burley's albedo `A` per channel (the profile's total).
pub fn albedo() -> [f64; 3] {
    crate::shader_constants::burley_s_albedo().1
}

/// The near part's share of the light, `A F(r_c)`, per channel.
pub fn near_weight() -> [f64; 3] {
    let (s, a) = (s_per_mm(), albedo());
    std::array::from_fn(|c| a[c] * radial_cdf(s[c], f64::from(BURLEY_NEAR_MM)))
}

/// The far part's share, `A (1 - F(r_c))`, per channel.
pub fn far_weight() -> [f64; 3] {
    let (s, a) = (s_per_mm(), albedo());
    std::array::from_fn(|c| a[c] * radial_tail(s[c], f64::from(BURLEY_NEAR_MM)))
}

/// Window radius in subsamples of a pixel at `px_per_mm` with supersampling
/// `s`: `r_c`, capped. Computed in f32 exactly as reference_burley_narrow.comp does.
pub fn radius(px_per_mm: f32, s: u32) -> u32 {
    let r = (BURLEY_NEAR_MM * px_per_mm * s as f32).ceil();
    (r.max(1.0) as u32).min(MAX_RADIUS)
}

/// `integral integral 1 / sqrt(x^2 + y^2) dx dy` over `[x1, x2] x [y1, y2]`,
/// exact: the antiderivative is `x asinh(y / |x|) + y asinh(x / |y|)` (0 on
/// the axes, continuous across them; its mixed derivative is `1 / r` in every
/// quadrant, which it is not without the absolute values).
pub fn rect_inv_r(x1: f64, x2: f64, y1: f64, y2: f64) -> f64 {
    let f = |x: f64, y: f64| {
        let a = if x != 0.0 {
            x * (y / x.abs()).asinh()
        } else {
            0.0
        };
        let b = if y != 0.0 {
            y * (x / y.abs()).asinh()
        } else {
            0.0
        };
        a + b
    };
    f(x2, y2) - f(x1, y2) - f(x2, y1) + f(x1, y1)
}

/// `R(r) / A` per channel (per mm^2).
pub fn profile(s: [f64; 3], r_mm: f64) -> [f64; 3] {
    s.map(|s| s * ((-s * r_mm).exp() + (-s * r_mm / 3.0).exp()) / (8.0 * PI * r_mm))
}

/// The integral of `R / A` over the square cell of side `h_mm` centred at
/// `(du, dv) h_mm` from the point (see the module doc).
pub fn cell_weight(s: [f64; 3], du: f64, dv: f64, h_mm: f64) -> [f64; 3] {
    let n = CELL_PARTS;
    let step = 1.0 / n as f64;
    let mut out = [0.0; 3];
    for j in 0..n {
        let y1 = dv - 0.5 + j as f64 * step;
        for i in 0..n {
            let x1 = du - 0.5 + i as f64 * step;
            let inv_r = rect_inv_r(x1, x1 + step, y1, y1 + step) * h_mm;
            let (cx, cy) = (x1 + 0.5 * step, y1 + 0.5 * step);
            let r = (cx * cx + cy * cy).sqrt() * h_mm;
            for c in 0..3 {
                let g = 0.5 * ((-s[c] * r).exp() + (-s[c] * r / 3.0).exp());
                out[c] += s[c] / (4.0 * PI) * g * inv_r;
            }
        }
    }
    out
}

/// `1 - e^(-x)` without the cancellation of small `x` (as the shader writes it).
fn one_minus_exp(x: f64) -> f64 {
    -(-x).exp_m1()
}

/// The weight of a subsample of area `h_mm^2` at distance `r_mm >= h_mm`
/// beyond [`BURLEY_CELL_REACH`]: the ring integral of `R / A` over `[r - h/2,
/// r + h/2]` (the CDF's difference, exact in `r`) times the cell's share of
/// the ring, `h / (2 pi r)`. A square's extent along any direction has the
/// variance of that interval (`h^2 / 12`), so the radial curvature of `R`
/// (blue's `e^(-s r)` at `s h = 0.9`) is integrated to second order, which
/// `R(r) h^2` (the midpoint) misses by `(s h)^2 / 24`.
pub fn ring_weight(s: [f64; 3], r_mm: f64, h_mm: f64) -> [f64; 3] {
    let a = r_mm - 0.5 * h_mm;
    s.map(|s| {
        let df = 0.25 * (-s * a).exp() * one_minus_exp(s * h_mm)
            + 0.75 * (-s * a / 3.0).exp() * one_minus_exp(s * h_mm / 3.0);
        df * h_mm / (2.0 * PI * r_mm)
    })
}

/// Whether a subsample at grid offset `(du, dv)` from the pixel's point takes
/// its cell's integral ([`cell_weight`]) rather than `R(r) A`.
pub fn in_cell_reach(du: f64, dv: f64) -> bool {
    let reach = f64::from(BURLEY_CELL_REACH) + 0.5;
    du.abs() <= reach && dv.abs() <= reach
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::skin::kernel::burley_profile;

    #[test]
    fn the_shared_constants_are_burley_profile() {
        let p = burley_profile();
        let (s, a) = (s_per_mm(), albedo());
        for c in 0..3 {
            assert!((s[c] - p.s()[c]).abs() < 1e-12 * s[c], "{s:?} {:?}", p.s());
            assert!((a[c] - p.albedo[c]).abs() < 1e-12);
        }
        // Blue's mean radius is 0.17 mm, red's 1.1 mm (the module doc's numbers).
        assert!((2.5 / s[2] - 0.1665).abs() < 1e-3 && (2.5 / s[0] - 1.12).abs() < 1e-2);
        let (near, far) = (near_weight(), far_weight());
        for (c, a) in a.iter().enumerate() {
            assert!((near[c] + far[c] - a).abs() < 1e-12);
        }
        assert!(
            (near_weight()[0] - 0.616).abs() < 1e-2,
            "{:?}",
            near_weight()
        );
    }

    #[test]
    fn the_inverse_distance_integral_is_exact() {
        // Against a fine midpoint sum on a cell away from the origin.
        let (x1, x2, y1, y2) = (0.5, 1.5, -0.5, 0.5);
        let n = 2000;
        let mut sum = 0.0;
        for j in 0..n {
            for i in 0..n {
                let x = x1 + (i as f64 + 0.5) / n as f64 * (x2 - x1);
                let y = y1 + (j as f64 + 0.5) / n as f64 * (y2 - y1);
                sum += 1.0 / (x * x + y * y).sqrt();
            }
        }
        sum *= (x2 - x1) * (y2 - y1) / (n * n) as f64;
        assert!((rect_inv_r(x1, x2, y1, y2) - sum).abs() < 1e-6, "{sum}");
        // The unit square at the origin: 2 asinh(1); the cell around the
        // origin is four of them.
        let q = 2.0 * 1f64.asinh();
        assert!((rect_inv_r(0.0, 1.0, 0.0, 1.0) - q).abs() < 1e-12);
        assert!((rect_inv_r(-0.5, 0.5, -0.5, 0.5) - 4.0 * q / 2.0).abs() < 1e-12);
    }

    #[test]
    fn cells_around_the_point_hold_the_cdf() {
        // The cells within reach tile a square around the point; with the
        // farther ones at R(r) A on a fine plane, the sum is the CDF's total.
        let s = s_per_mm();
        for (h, offset) in [(0.06, 0.5), (0.06, 0.0), (0.04, 0.0)] {
            let mut sum = [0.0; 3];
            let n = (6.0 / h) as i64;
            for j in -n..=n {
                for i in -n..=n {
                    let (du, dv) = (i as f64 + offset, j as f64 + offset);
                    let r = (du * du + dv * dv).sqrt() * h;
                    let w = if in_cell_reach(du, dv) {
                        cell_weight(s, du, dv, h)
                    } else {
                        ring_weight(s, r, h)
                    };
                    for c in 0..3 {
                        sum[c] += w[c];
                    }
                }
            }
            // The square reaches 6 mm: red keeps 1 - F(6 mm) short of 1.
            for c in 0..3 {
                let want = radial_cdf(s[c], 6.0 * 1.0);
                assert!(
                    (sum[c] / want - 1.0).abs() < 0.01 + (1.0 - want),
                    "h {h}, offset {offset}, channel {c}: {sum:?}"
                );
            }
            // Blue is within the square: its sum is its total within 0.6%
            // (measured 0.995 at s h = 0.9, the 720p close-up's 2x grid: the
            // 4x4 parts' midpoint in g; normalised away in the truth).
            assert!(
                (sum[2] - 1.0).abs() < 6e-3,
                "h {h}, offset {offset}: {sum:?}"
            );
        }
    }

    #[test]
    fn the_window_covers_the_near_part() {
        assert_eq!(radius(8.5, 2), 17);
        assert_eq!(radius(1000.0, 3), MAX_RADIUS);
        assert_eq!(radius(0.01, 1), 1);
    }
}

#[cfg(test)]
mod edge_tests {
    use super::*;
    use crate::skin::burley::marginal_tail;

    #[test]
    fn the_weights_see_an_edge_as_the_closed_form_does() {
        // A pixel half a pixel left of an edge at 8.5 px/mm, 2x supersampled:
        // the weights' share left of the edge against 1 - T(x) of the marginal.
        let s = s_per_mm();
        let h = 1.0 / 17.0;
        let n = (1.0 / h) as i64 + 2;
        for c in 0..3 {
            let (mut left, mut all) = (0.0, 0.0);
            for j in -n..=n {
                for i in -n..=n {
                    let (du, dv) = (i as f64 + 0.5, j as f64 + 0.5);
                    let r = (du * du + dv * dv).sqrt() * h;
                    if r >= f64::from(BURLEY_NEAR_MM) {
                        continue;
                    }
                    let w = if in_cell_reach(du, dv) {
                        cell_weight(s, du, dv, h)
                    } else {
                        ring_weight(s, r, h)
                    };
                    all += w[c];
                    if du < 1.0 {
                        left += w[c];
                    }
                }
            }
            let got = left / all;
            let want = 1.0 - marginal_tail(s[c], h);
            // Red's far part (38%) is the gather's: only green and blue (98%
            // and 99.5% near) are the near part's to match (measured 0.7100
            // against 0.7044, 0.7610 against 0.7603).
            if c > 0 {
                assert!(
                    (got - want).abs() < 0.01,
                    "channel {c}: {got:.4}, want {want:.4}"
                );
            }
        }
    }
}
