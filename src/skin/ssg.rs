//! Screen-space sum-of-Gaussians SSS (Jimenez's thesis, ch. 4, "SS Full").
//!
//! The diffusion profile is d'Eon's sum of Gaussians (Table 4.2). Each
//! Gaussian is applied as a separable 7-tap blur (Listing 4.1) on top of the
//! previous, narrower one, so only the *incremental* variance
//! `v_i - v_{i-1}` is blurred per step (Gaussians convolve by adding
//! variances). The running sum is accumulated with alpha blending using
//! the renormalised weights `w'_i` of eq. 4.8, which is why no render target
//! per Gaussian is needed.
//!
//! The kernel width in pixels is driven by the stretch factors of
//! eq. 4.1-4.4: further away and steeper (larger depth gradient) means a
//! narrower kernel; [`Stretch`] holds their `alpha`, `beta`, `gamma`.

use std::str::FromStr;

use anyhow::{bail, Result};

use super::kernel::DEMO_UNIT_MM;
use super::profile::{
    FOUR_GAUSSIAN_VARIANCES_MM2, FOUR_GAUSSIAN_WEIGHTS_RGB, SIX_GAUSSIAN_VARIANCES_MM2,
    SIX_GAUSSIAN_WEIGHTS_RGB,
};
use crate::view::ViewScale;

/// Which of d'Eon's skin fits (Table 4.2) to use.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub enum GaussianFit {
    /// Four Gaussians: one Gaussian step fewer, coarser profile.
    Four,
    /// Six Gaussians: the fit d'Eon uses for the reference renders.
    Six,
}

impl GaussianFit {
    /// Every fit, for listings and exhaustive tests.
    pub const ALL: [GaussianFit; 2] = [GaussianFit::Four, GaussianFit::Six];

    /// Canonical name, accepted back by `FromStr`.
    pub fn name(self) -> &'static str {
        match self {
            GaussianFit::Four => "4",
            GaussianFit::Six => "6",
        }
    }

    /// Variances (mm^2) in increasing order.
    pub fn variances(self) -> &'static [f32] {
        match self {
            GaussianFit::Four => &FOUR_GAUSSIAN_VARIANCES_MM2,
            GaussianFit::Six => &SIX_GAUSSIAN_VARIANCES_MM2,
        }
    }

    /// Original weights `w_i` (R, G, B), one row per variance.
    pub fn weights(self) -> &'static [[f32; 3]] {
        match self {
            GaussianFit::Four => &FOUR_GAUSSIAN_WEIGHTS_RGB,
            GaussianFit::Six => &SIX_GAUSSIAN_WEIGHTS_RGB,
        }
    }
}

impl FromStr for GaussianFit {
    type Err = anyhow::Error;

    fn from_str(s: &str) -> Result<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "4" | "four" => Ok(GaussianFit::Four),
            "6" | "six" => Ok(GaussianFit::Six),
            _ => bail!("unknown Gaussian fit {s:?}; valid fits: 4 (or four), 6 (or six)"),
        }
    }
}

/// Blend factors `w'_i` of eq. 4.8: `w'_i = w_i / sum_{j<=i} w_j` per channel
/// (0 where that sum is 0).
///
/// Why: blending `c_src * w'_i + c_dst * (1 - w'_i)` (eq. 4.9) after every
/// Gaussian keeps the running result normalised, i.e. after step `i` the
/// target holds `sum_{j<=i} w_j G_j / sum_{j<=i} w_j`. So the sum can stop
/// at any step (LOD) and still be a proper weighted average, and after the
/// last step it equals `sum_j w_j G_j` (the weights of a channel sum to 1).
/// `w'_0` is 1: the first Gaussian overwrites (it is the unblurred image).
pub fn blend_weights(fit: GaussianFit) -> Vec<[f32; 3]> {
    let mut partial = [0.0f32; 3];
    fit.weights()
        .iter()
        .map(|w| {
            let mut out = [0.0f32; 3];
            for c in 0..3 {
                partial[c] += w[c];
                out[c] = if partial[c] > 0.0 {
                    w[c] / partial[c]
                } else {
                    0.0
                };
            }
            out
        })
        .collect()
}

/// One blur step of the chain (every Gaussian after the first).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SsgGaussian {
    /// 1-based index as in the thesis: 2..=n.
    pub index: usize,
    /// `sqrt(v_i - v_{i-1})`: the blur is applied on top of the previous
    /// Gaussian's result, so only the variance difference is added.
    pub incremental_std_mm: f32,
    /// Blend factor `w'_i` (eq. 4.8) per channel.
    pub blend: [f32; 3],
}

/// The blur steps of a fit, narrowest first.
///
/// The first Gaussian (variance 0.0064 mm^2, sigma 0.08 mm) is narrower
/// than a pixel at any sensible distance, so the unblurred image stands in
/// for it (thesis, section 4.2.1) and it gets no step of its own.
pub fn ssg_gaussians(fit: GaussianFit) -> Vec<SsgGaussian> {
    let v = fit.variances();
    let blend = blend_weights(fit);
    (1..v.len())
        .map(|i| SsgGaussian {
            index: i + 1,
            incremental_std_mm: (v[i] - v[i - 1]).sqrt(),
            blend: blend[i],
        })
        .collect()
}

/// Parameters of the stretch factors, eq. 4.1-4.2:
/// `s = alpha / (d + beta * min(|grad d|, gamma))`.
///
/// Units: Listing 4.1 steps its 7 taps by `s * sigma / 3` pixels, so on a
/// flat surface `alpha / (3 d)` is the number of pixels one millimetre of
/// sigma spans at view depth `d` (scene units).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Stretch {
    /// Global SSS level: three times the pixels per millimetre at unit
    /// view depth.
    pub alpha: f32,
    /// How strongly depth gradients (grazing surfaces, silhouettes) shrink
    /// the kernel.
    pub beta: f32,
    /// Cap on the depth gradient (scene units per pixel).
    pub gamma: f32,
}

impl Stretch {
    /// The thesis' values, chosen empirically for a head 1 unit tall, a
    /// 20 degree vertical field of view and a 720 pixel high viewport.
    ///
    /// Its alpha is not that view's true scale: with a 230 mm head,
    /// `alpha / 3 = 10.5` px per mm at depth 1 against a true
    /// `720 / (2 tan(10 deg) 230) = 8.88`, so it blurs 18% wider than the
    /// profile. [`Stretch::for_view`] derives alpha from the view instead
    /// and keeps only beta and gamma from here.
    pub const THESIS: Stretch = Stretch {
        alpha: 31.5,
        beta: 800.0,
        gamma: 0.001,
    };

    /// The stretch for a view, at the scene's true scale.
    ///
    /// With the focal length in pixels `f = height_px / (2 tan(fovy/2))`, a
    /// length `l` (scene units) at view depth `d` spans `l f / d` pixels, so
    /// one millimetre spans `f / (mm_per_unit d)`:
    /// * `alpha = 3 f / mm_per_unit`, so that `alpha / (3 d)` is exactly the
    ///   pixels per mm at depth `d` (the 3 of Listing 4.1) and a Gaussian of
    ///   sigma mm spans sigma mm of the surface on screen;
    /// * `beta = 800 f / f_T`, with `f_T = 720 / (2 tan(10 deg))` the
    ///   thesis' focal length: the per-pixel depth gradient of a surface of
    ///   slope `m` is `m d / f`, so `beta |grad d| / d = 800 m / f_T` is the
    ///   same function of the slope as in the thesis, on any view;
    /// * `gamma = 0.001 k f_T / f`, `k = 230 / mm_per_unit`: the gradient cap
    ///   (scene units per pixel), kept at the thesis' slope for the same
    ///   depth in millimetres (its unit is 230 mm, [`DEMO_UNIT_MM`]).
    ///
    /// At 720 px and 20 degrees beta and gamma are the thesis' (scaled by
    /// `k` for gamma) and alpha is `31.5 / 1.183` for a 230 mm unit.
    pub fn for_view(height_px: u32, fovy_rad: f32, mm_per_unit: f32) -> Stretch {
        let k = DEMO_UNIT_MM / mm_per_unit;
        let scale = ViewScale::new(height_px, fovy_rad, mm_per_unit);
        let tan_half = scale.tan_half_fovy;
        let focal_px = scale.focal_px();
        // f / f_T, as (height/720) (tan 10 / tan(fovy/2)): exactly
        // height/720 at 20 degrees.
        let h = height_px as f32 / 720.0;
        let focal_ratio = h * (10f32.to_radians().tan() / tan_half);
        Stretch {
            alpha: 3.0 * focal_px / mm_per_unit,
            beta: Self::THESIS.beta * focal_ratio,
            gamma: Self::THESIS.gamma * k / focal_ratio,
        }
    }

    /// Pixels per millimetre at view depth `d` on a flat surface (no
    /// gradient, strength 1): `alpha / (3 d)`.
    pub fn px_per_mm(&self, depth: f32) -> f32 {
        self.alpha / (3.0 * depth)
    }

    /// Stretch factors `[s_x, s_y]` of eq. 4.1-4.2 at pixel `(x, y)`,
    /// *before* the per-pixel strength of eq. 4.3-4.4.
    ///
    /// The gradient is the central difference of texel fetches clamped to
    /// the edge, `0.5 * (d[x+1] - d[x-1])`, rather than `ddx`/`ddy`: the
    /// shader runs on a full-screen quad where `ddx` of a fetched value
    /// would be a one-sided difference that depends on the 2x2 quad the
    /// pixel falls in; the central difference is symmetric and exactly
    /// reproducible on the CPU. Evaluated in f32 in this order:
    /// `alpha / (d + beta * min(|g|, gamma))`.
    pub fn factors(
        &self,
        linear_depth: &[f32],
        width: usize,
        height: usize,
        x: usize,
        y: usize,
    ) -> [f32; 2] {
        let at = |xx: usize, yy: usize| linear_depth[yy * width + xx];
        let d = at(x, y);
        let gx = 0.5 * (at((x + 1).min(width - 1), y) - at(x.saturating_sub(1), y));
        let gy = 0.5 * (at(x, (y + 1).min(height - 1)) - at(x, y.saturating_sub(1)));
        let s = |g: f32| self.alpha / (d + self.beta * g.abs().min(self.gamma));
        [s(gx), s(gy)]
    }
}

/// The 7 tap weights of Listing 4.1, shared with ssg_blur.glsl and
/// tsd_blur.glsl through `crate::shader_constants`.
pub use crate::shader_constants::LISTING_4_1_WEIGHTS;

/// Eq. 4.6 with the thesis' 0.5 factor instead of 2: the view depth (scene
/// units) beyond which Gaussian `i` is skipped. The thesis found 0.5 turns
/// narrow Gaussians off sooner without visible popping. With alpha at the
/// view's true scale ([`Stretch::for_view`]) that is where the step's 3
/// sigma span less than 2 pixels (sigma less than 2/3 pixel).
pub fn lod_depth(incremental_std_mm: f32, alpha: f32) -> f32 {
    0.5 * incremental_std_mm * alpha
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Table 4.2, `w'_i` columns as printed.
    const TABLE_FOUR: [[f32; 3]; 4] = [
        [1.0, 1.0, 1.0],
        [0.3251, 0.45, 0.3583],
        [0.34, 0.1864, 0.0],
        [0.46, 0.0, 0.0402],
    ];
    const TABLE_SIX: [[f32; 3]; 6] = [
        [1.0, 1.0, 1.0],
        [0.3, 0.424, 0.346],
        [0.261, 0.2, 0.0],
        [0.2, 0.007, 0.007],
        [0.388, 0.004, 0.0],
        [0.078, 0.0, 0.0],
    ];

    #[test]
    fn blend_weights_match_table_4_2() {
        for (fit, table) in [
            (GaussianFit::Four, &TABLE_FOUR[..]),
            (GaussianFit::Six, &TABLE_SIX[..]),
        ] {
            let got = blend_weights(fit);
            assert_eq!(got.len(), table.len());
            for (i, (g, t)) in got.iter().zip(table).enumerate() {
                for c in 0..3 {
                    assert!(
                        (g[c] - t[c]).abs() <= 0.0015,
                        "{fit:?} row {} channel {c}: {} vs printed {}",
                        i + 1,
                        g[c],
                        t[c]
                    );
                }
            }
        }
    }

    #[test]
    fn blending_reproduces_the_weighted_sum() {
        // Blend distinct "Gaussian results" g_i with eq. 4.9 and compare with
        // sum w_i g_i: the defining property of w'.
        for fit in GaussianFit::ALL {
            let w = fit.weights();
            let wp = blend_weights(fit);
            for c in 0..3 {
                let g = |i: usize| 1.0 + i as f32 * 0.37;
                let mut acc = 0.0f32;
                for (i, b) in wp.iter().enumerate() {
                    acc = g(i) * b[c] + acc * (1.0 - b[c]);
                }
                // The running sum is normalised by sum w_i, which is 0.9999
                // rather than 1 for some 4-Gaussian channels.
                let total: f32 = (0..w.len()).map(|i| w[i][c]).sum();
                let want: f32 = (0..w.len()).map(|i| w[i][c] * g(i)).sum::<f32>() / total;
                assert!((acc - want).abs() < 1e-4, "{fit:?} c{c}: {acc} vs {want}");
            }
        }
    }

    #[test]
    fn gaussian_steps() {
        let four = ssg_gaussians(GaussianFit::Four);
        assert_eq!(four.len(), 3);
        assert_eq!(four.iter().map(|g| g.index).collect::<Vec<_>>(), [2, 3, 4]);
        // The thesis' worked example: sqrt(2.0062 - 0.2719) = sqrt(1.7343).
        let widest = four[2];
        assert_eq!(widest.incremental_std_mm, (2.0062f32 - 0.2719).sqrt());
        assert!((widest.incremental_std_mm - 1.7343f32.sqrt()).abs() < 1e-6);
        assert_eq!(widest.blend, blend_weights(GaussianFit::Four)[3]);
        let six = ssg_gaussians(GaussianFit::Six);
        assert_eq!(six.len(), 5);
        assert_eq!(six[0].index, 2);
        assert!((six[0].incremental_std_mm - (0.0484f32 - 0.0064).sqrt()).abs() < 1e-7);
        // Variances add up again.
        let total: f32 = six.iter().map(|g| g.incremental_std_mm.powi(2)).sum();
        assert!((total + 0.0064 - 7.41).abs() < 1e-5);
    }

    #[test]
    fn fit_names_round_trip() {
        for fit in GaussianFit::ALL {
            assert_eq!(fit.name().parse::<GaussianFit>().unwrap(), fit);
        }
        assert_eq!("Four".parse::<GaussianFit>().unwrap(), GaussianFit::Four);
        assert_eq!(" six ".parse::<GaussianFit>().unwrap(), GaussianFit::Six);
        assert!("5".parse::<GaussianFit>().is_err());
        assert_eq!(GaussianFit::Six.variances().len(), 6);
        assert_eq!(GaussianFit::Four.weights().len(), 4);
    }

    #[test]
    fn for_view_at_the_thesis_setup() {
        let s = Stretch::for_view(720, 20f32.to_radians(), DEMO_UNIT_MM);
        // beta and gamma are the thesis' exactly.
        assert_eq!(s.beta, Stretch::THESIS.beta);
        assert_eq!(s.gamma, Stretch::THESIS.gamma);
        // True scale: 720 / (2 tan 10 deg 230 mm) = 8.876 px per mm at
        // depth 1; the thesis' 31.5 / 3 = 10.5 is 18.3% wider.
        assert!((s.px_per_mm(1.0) - 8.876).abs() < 1e-3, "{}", s.alpha);
        let ratio = Stretch::THESIS.alpha / s.alpha;
        assert!((ratio - 1.183).abs() < 1e-3, "{ratio}");
    }

    #[test]
    fn alpha_is_the_projected_millimetre() {
        // One mm at depth d, projected: height / (2 d tan(fovy/2) mm_per_unit)
        // pixels (crate::view::ViewScale::px_per_mm), for several views.
        for (h, fov_deg, mm, d) in [
            (720u32, 20f32, 230f32, 1.0f32),
            (1080, 35.0, 10.0, 37.0),
            (2160, 60.0, 48.3, 4.5),
        ] {
            let s = Stretch::for_view(h, fov_deg.to_radians(), mm);
            let want = h as f32 / (2.0 * d * (0.5 * fov_deg.to_radians()).tan() * mm);
            assert!((s.px_per_mm(d) - want).abs() < 1e-5 * want, "{h} {fov_deg}");
            let flat = vec![d; 9];
            let [sx, sy] = s.factors(&flat, 3, 3, 1, 1);
            assert!((sx / 3.0 - want).abs() < 1e-5 * want && sx == sy);
        }
    }

    #[test]
    fn for_view_scaling_law() {
        let fov = 20f32.to_radians();
        let a = Stretch::for_view(720, fov, 230.0);
        let b = Stretch::for_view(1440, fov, 230.0);
        assert!((b.alpha - 2.0 * a.alpha).abs() < 1e-4);
        assert!((b.beta - 2.0 * a.beta).abs() < 1e-3);
        assert!((b.gamma - 0.5 * a.gamma).abs() < 1e-9);
        // Scene in millimetres (1 unit = 1 mm): alpha and gamma scale by 230.
        let mm = Stretch::for_view(720, fov, 1.0);
        assert!((mm.alpha - 230.0 * a.alpha).abs() < 1e-2);
        assert!((mm.gamma - 230.0 * a.gamma).abs() < 1e-6);
        assert_eq!(mm.beta, a.beta);
        // A wider field of view makes everything smaller on screen: alpha
        // and beta shrink with the focal length, the gradient cap grows.
        let wide = Stretch::for_view(720, 60f32.to_radians(), 230.0);
        let f = 10f32.to_radians().tan() / 30f32.to_radians().tan();
        assert!((wide.alpha - a.alpha * f).abs() < 1e-4);
        assert!((wide.beta - a.beta * f).abs() < 1e-3);
        assert!((wide.gamma - a.gamma / f).abs() < 1e-8);
    }

    #[test]
    fn depth_gradient_term_depends_on_the_slope_only() {
        // A plane of slope m seen at depth d: per-pixel gradient m d / f.
        // The shrink d / (d + beta |g|) must be the same on every view.
        let m = 0.4f32;
        let shrink = |h: u32, fov_deg: f32, mm: f32, d_mm: f32| {
            let s = Stretch::for_view(h, fov_deg.to_radians(), mm);
            let d = d_mm / mm;
            let f = h as f32 / (2.0 * (0.5 * fov_deg.to_radians()).tan());
            let g = m * d / f;
            d / (d + s.beta * g.min(s.gamma))
        };
        let base = shrink(720, 20.0, 230.0, 600.0);
        for (h, fov, mm) in [(1080, 20.0, 10.0), (720, 45.0, 48.3), (2160, 70.0, 1.0)] {
            let other = shrink(h, fov, mm, 600.0);
            assert!(
                (other - base).abs() < 1e-5,
                "{h} {fov} {mm}: {other} vs {base}"
            );
        }
    }

    #[test]
    fn stretch_factors_follow_eq_4_1() {
        let (w, h) = (4, 3);
        // Depth grows by 0.0004 per pixel in x, 0.01 per pixel in y.
        let depth: Vec<f32> = (0..w * h)
            .map(|i| 2.0 + (i % w) as f32 * 0.0004 + (i / w) as f32 * 0.01)
            .collect();
        let s = Stretch::THESIS;
        let [sx, sy] = s.factors(&depth, w, h, 1, 1);
        let d = depth[w + 1];
        // Depth differences of ~2.0 values carry f32 rounding (~2e-7), which
        // beta = 800 amplifies: compare with a relative tolerance.
        let close = |a: f32, b: f32| (a - b).abs() < 1e-3 * b;
        assert!(close(sx, 31.5 / (d + 800.0 * 0.0004)), "{sx}");
        // The y gradient is capped at gamma.
        assert!(close(sy, 31.5 / (d + 800.0 * 0.001)), "{sy}");
        // Edges: one-sided neighbour clamped, still halved.
        let [sx0, _] = s.factors(&depth, w, h, 0, 1);
        assert!(close(sx0, 31.5 / (depth[w] + 800.0 * 0.0002)), "{sx0}");
        // Flat depth: alpha / d.
        let flat = vec![1.5; w * h];
        assert_eq!(s.factors(&flat, w, h, 3, 2), [31.5 / 1.5; 2]);
    }

    #[test]
    fn listing_weights_sum_to_one() {
        let s: f32 = LISTING_4_1_WEIGHTS.iter().sum();
        assert!((s - 1.0).abs() < 1e-6);
    }

    #[test]
    fn lod_depth_is_half_sigma_alpha() {
        assert_eq!(lod_depth(2.0, 31.5), 31.5);
    }
}
