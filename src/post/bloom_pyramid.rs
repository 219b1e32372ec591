//! The bloom's numbers, with no Vulkan (a pure file: tests/suite/layers.rs):
//! the pyramid's parameters, its Gaussian weights, the closed form of the
//! halo it spreads a pixel into, and a CPU mirror of one axis of it.
//!
//! The bloom imitates the point-spread function of the optics that filmed the
//! frame (thesis ch. 4.2: "it simulates the point-spread-function of the
//! optical system used to capture (render) the image"; d'Eon and Luebke's,
//! after Pharr and Humphreys, ch. 11.1). So it is linear and has no bright
//! pass: a point-spread function acts on all light, and a threshold would
//! make the result depend on the exposure's split. It is written as an
//! energy-conserving mix, `out = (1 - s) in + s B(in)`, with `B` a
//! normalised blur, so a uniform frame is left as it is and the light a
//! pixel loses to its halo is the light the halo holds.
//!
//! `B` is a pyramid (`post::bloom` runs it): level `k` (1..=4) holds texel
//! `m` at full-resolution pixel `2^k m` (sample-centred, so the system is
//! symmetric about every pixel on the coarsest grid), made from level
//! `k - 1` by `[1, 2, 1] / 4` on each axis (four bilinear fetches half a texel
//! off, an exact 3 x 3 tent), blurred by a 7-tap Gaussian of one texel per
//! axis, and read back at full resolution bilinearly; `B` is the levels'
//! weighted sum. Parameters and why:
//!
//! - [`LEVELS`] = 4: the widest level's halo has sigma 17.2 px (an impulse
//!   on its grid), 2.4 % of a 720p frame's height: a glare skirt, not a haze.
//!   Its level is 80 x 45 texels at 720p, so clamping at the frame's border
//!   touches only its outer three texels.
//! - [`BLUR_SIGMA`] = 1 texel, radius 3 (3 sigma): the narrowest Gaussian
//!   that hides the level's texel grid under the bilinear read-back (the tent
//!   alone gives a piecewise-linear, blocky halo); per level the sigma in
//!   pixels doubles.
//! - [`LEVEL_WEIGHTS`] equal: the same energy per octave of radius, which is
//!   a point-spread function falling as `1 / r^2` between the narrowest and
//!   the widest level (the energy of `r^-2` in an annulus `[r, 2 r]` is
//!   `2 pi ln 2` whatever `r`), the fall-off of glare spread functions.
//! - [`STRENGTH`] = 0.1: the share of a pixel's light the optics scatter
//!   into its halo. A look parameter (the sources give none): a pixel keeps
//!   90 % of its light, so an edge keeps 90 % of its contrast, while a
//!   highlight several times the white point shows a visible skirt. Every
//!   test reads it from here, none depends on its value.

use crate::shader_constants::{BLOOM_BLUR_RADIUS, BLOOM_LEVELS};

/// Levels of the pyramid: half to sixteenth resolution.
pub const LEVELS: usize = BLOOM_LEVELS;
/// Taps of the per-level Gaussian each side of the centre.
pub const BLUR_RADIUS: usize = BLOOM_BLUR_RADIUS as usize;
/// Standard deviation of the per-level Gaussian, in that level's texels.
pub const BLUR_SIGMA: f64 = 1.0;
/// Each level's share of the blur `B` (they sum to 1).
pub const LEVEL_WEIGHTS: [f32; LEVELS] = [0.25; LEVELS];
/// The share `s` of the light spread into the halo.
pub const STRENGTH: f32 = 0.1;

// A mix: the halo takes a share of the light, never all of it.
const _: () = assert!(STRENGTH > 0.0 && STRENGTH < 1.0);

/// The per-level Gaussian's weights for offsets 0..=R (the same either
/// side), normalised so the 2R + 1 taps sum to 1: the blur keeps a uniform
/// level uniform.
pub fn blur_weights() -> [f32; BLUR_RADIUS + 1] {
    let g = |i: usize| (-((i * i) as f64) / (2.0 * BLUR_SIGMA * BLUR_SIGMA)).exp();
    let total: f64 = g(0) + 2.0 * (1..=BLUR_RADIUS).map(g).sum::<f64>();
    std::array::from_fn(|i| (g(i) / total) as f32)
}

/// The truncated Gaussian's variance in texels^2 (`sum i^2 w_|i|`), a little
/// under `BLUR_SIGMA^2` (the tails past 3 sigma are cut).
pub fn blur_variance() -> f64 {
    let w = blur_weights();
    (1..=BLUR_RADIUS)
        .map(|i| 2.0 * (i * i) as f64 * f64::from(w[i]))
        .sum()
}

/// The size of level `k` (1..=LEVELS) of a `width` x `height` frame:
/// `ceil(n / 2^k)` per axis, so its last texel still covers the frame's last
/// pixel (texel `m` sits at pixel `2^k m`).
pub fn level_extent(width: u32, height: u32, k: usize) -> (u32, u32) {
    let d = 1u32 << k;
    (width.div_ceil(d), height.div_ceil(d))
}

/// The closed form of one level's halo, per axis, in pixels^2, for a pixel
/// on the level's grid (a multiple of `2^k`, far from the border): the
/// `[1, 2, 1] / 4` reductions of an impulse on the grid keep only its centre
/// texel (their spread falls on the texels that are dropped), the Gaussian
/// adds `4^k` times its variance (texels of `2^k` pixels), and the bilinear
/// read-back is a tent of half width `h = 2^k`, whose discrete variance is
/// `(h^2 - 1) / 6`.
pub fn level_variance(k: usize) -> f64 {
    let h2 = 4f64.powi(k as i32);
    h2 * blur_variance() + (h2 - 1.0) / 6.0
}

/// The same averaged over the `2^k` positions of a pixel on the grid: the
/// reductions then add their own spread, `(4^k - 1) / 6` (a `[1, 2, 1] / 4`
/// of variance 1/2 texel^2 at each level `j`, texels of `2^(j-1)` pixels).
pub fn level_variance_mean_phase(k: usize) -> f64 {
    let h2 = 4f64.powi(k as i32);
    level_variance(k) + (h2 - 1.0) / 6.0
}

/// The halo's variance per axis for a pixel on the coarsest grid: the
/// levels' mixture (every level centred on the pixel), `sum w_k var_k`.
pub fn halo_variance() -> f64 {
    (1..=LEVELS)
        .map(|k| f64::from(LEVEL_WEIGHTS[k - 1]) * level_variance(k))
        .sum()
}

/// Pixels apart of the coarsest grid's points: where a pixel's halo is
/// symmetric about it and has [`halo_variance`].
pub const COARSEST_STEP: usize = 1 << LEVELS;

fn clamped(x: &[f64], i: isize) -> f64 {
    x[i.clamp(0, x.len() as isize - 1) as usize]
}

/// One level's reduction, along one axis: texel `m` is `[1, 2, 1] / 4` of
/// texels `2m - 1, 2m, 2m + 1` below, clamped at the border (what the four
/// half-texel-off bilinear fetches give).
pub fn reduce_1d(x: &[f64]) -> Vec<f64> {
    (0..x.len().div_ceil(2))
        .map(|m| {
            let c = 2 * m as isize;
            (clamped(x, c - 1) + 2.0 * clamped(x, c) + clamped(x, c + 1)) / 4.0
        })
        .collect()
}

/// The per-level Gaussian along one axis, clamped at the border.
pub fn blur_1d(x: &[f64]) -> Vec<f64> {
    let w = blur_weights();
    let r = BLUR_RADIUS as isize;
    (0..x.len() as isize)
        .map(|m| {
            (-r..=r)
                .map(|i| f64::from(w[i.unsigned_abs()]) * clamped(x, m + i))
                .sum()
        })
        .collect()
}

/// Level `k` read back at `n` full-resolution pixels: pixel `p` linearly
/// between texels `floor(p / 2^k)` and the next, clamped.
pub fn upsample_1d(level: &[f64], k: usize, n: usize) -> Vec<f64> {
    let h = (1usize << k) as f64;
    (0..n)
        .map(|p| {
            let u = p as f64 / h;
            let i = u.floor() as isize;
            let f = u - u.floor();
            (1.0 - f) * clamped(level, i) + f * clamped(level, i + 1)
        })
        .collect()
}

/// One level of the pyramid along one axis: `k` reductions, the blur, the
/// read-back (the CPU mirror of a separable level).
pub fn level_1d(x: &[f64], k: usize) -> Vec<f64> {
    let mut l = x.to_vec();
    for _ in 0..k {
        l = reduce_1d(&l);
    }
    upsample_1d(&blur_1d(&l), k, x.len())
}

/// The halo `B` of a unit pixel at `(x, y)` in a `w` x `h` frame, row-major:
/// every stage is separable, so each level is the outer product of its two
/// axes, and `B` is their weighted sum.
pub fn halo(w: usize, h: usize, x: usize, y: usize) -> Vec<f64> {
    let unit = |n: usize, at: usize| {
        let mut v = vec![0.0; n];
        v[at] = 1.0;
        v
    };
    let mut out = vec![0.0; w * h];
    for k in 1..=LEVELS {
        let (rx, ry) = (level_1d(&unit(w, x), k), level_1d(&unit(h, y), k));
        let wk = f64::from(LEVEL_WEIGHTS[k - 1]);
        for (j, &b) in ry.iter().enumerate() {
            for (i, &a) in rx.iter().enumerate() {
                out[j * w + i] += wk * a * b;
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit(n: usize, at: usize) -> Vec<f64> {
        let mut v = vec![0.0; n];
        v[at] = 1.0;
        v
    }

    fn moments(r: &[f64], at: usize) -> (f64, f64, f64) {
        let mass: f64 = r.iter().sum();
        let mean = r.iter().enumerate().map(|(i, v)| i as f64 * v).sum::<f64>() / mass;
        let var = r
            .iter()
            .enumerate()
            .map(|(i, v)| (i as f64 - at as f64).powi(2) * v)
            .sum::<f64>()
            / mass;
        (mass, mean, var)
    }

    #[test]
    fn the_weights_are_normalised_and_the_blur_is_the_stated_gaussian() {
        let w = blur_weights();
        let total = w[0] + 2.0 * w[1..].iter().sum::<f32>();
        assert!((total - 1.0).abs() < 1e-6, "{total}");
        assert!(w.windows(2).all(|p| p[0] > p[1]), "{w:?}");
        // Cut at 3 sigma: 0.4 % of the variance is lost, no more.
        let v = blur_variance();
        assert!(
            v < BLUR_SIGMA.powi(2) && v > 0.995 * BLUR_SIGMA.powi(2),
            "{v}"
        );
        let levels: f32 = LEVEL_WEIGHTS.iter().sum();
        assert!((levels - 1.0).abs() < 1e-6);
    }

    #[test]
    fn level_extents_cover_the_frame() {
        assert_eq!(level_extent(1280, 720, 1), (640, 360));
        assert_eq!(level_extent(1280, 720, 4), (80, 45));
        assert_eq!(level_extent(97, 65, 1), (49, 33));
        assert_eq!(level_extent(1, 1, 4), (1, 1));
        // The last pixel's texel exists: (n - 1) >> k < extent.
        for n in 1..200u32 {
            for k in 1..=LEVELS {
                assert!((n - 1) >> k < level_extent(n, n, k).0);
            }
        }
    }

    // A uniform signal stays uniform through every stage, borders included
    // (within the f32 rounding of the weights' sum, 6e-8: the GPU's weights).
    #[test]
    fn a_uniform_signal_stays_uniform() {
        for n in [1, 2, 7, 64, 97] {
            let x = vec![3.5; n];
            for k in 1..=LEVELS {
                for v in level_1d(&x, k) {
                    assert!((v - 3.5).abs() < 3.5e-7, "n {n} level {k}: {v}");
                }
            }
        }
    }

    // The closed form against the mirror: an impulse on the level's grid has
    // exactly `level_variance`; over its 2^k phases, on average, the
    // reductions' own spread too. Every phase keeps its mass (the halo holds
    // the light the pixel lost) and, on the grid, its centre.
    #[test]
    fn the_closed_form_is_the_mirrors_variance() {
        let n = 512;
        for k in 1..=LEVELS {
            let at = 256;
            let (mass, mean, var) = moments(&level_1d(&unit(n, at), k), at);
            assert!((mass - 1.0).abs() < 1e-7, "{mass}");
            assert!((mean - at as f64).abs() < 1e-9, "{mean}");
            assert!(
                (var - level_variance(k)).abs() < 1e-6 * var,
                "level {k}: {var} vs {}",
                level_variance(k)
            );
            let h = 1 << k;
            let mut sum = 0.0;
            for phase in 0..h {
                let (mass, _, var) = moments(&level_1d(&unit(n, at + phase), k), at + phase);
                assert!((mass - 1.0).abs() < 1e-7);
                sum += var;
            }
            let mean_var = sum / h as f64;
            assert!(
                (mean_var - level_variance_mean_phase(k)).abs() < 1e-6 * mean_var,
                "level {k}: {mean_var} vs {}",
                level_variance_mean_phase(k)
            );
        }
        let sigma = halo_variance().sqrt();
        assert!((9.0..11.0).contains(&sigma), "{sigma}");
    }

    // On the coarsest grid the 2D halo is symmetric about the pixel (both
    // axes and the diagonal) and falls monotonically along each axis.
    #[test]
    fn the_halo_of_a_grid_pixel_is_symmetric_and_falls() {
        let (w, h) = (256, 256);
        let (x, y) = (8 * COARSEST_STEP, 8 * COARSEST_STEP);
        let b = halo(w, h, x, y);
        let at = |i: usize, j: usize| b[j * w + i];
        for d in 1..48 {
            let r = at(x + d, y);
            assert!((r - at(x - d, y)).abs() < 1e-15 && (r - at(x, y + d)).abs() < 1e-15);
            assert!((r - at(x, y - d)).abs() < 1e-15);
            assert!(r < at(x + d - 1, y), "not falling at {d}");
        }
        let mass: f64 = b.iter().sum();
        assert!((mass - 1.0).abs() < 1e-7, "{mass}");
        let var_x: f64 = b
            .iter()
            .enumerate()
            .map(|(i, v)| ((i % w) as f64 - x as f64).powi(2) * v)
            .sum();
        assert!((var_x - halo_variance()).abs() < 1e-6 * var_x, "{var_x}");
    }
}
