//! Burley's normalized diffusion (Christensen & Burley 2015, "Approximate
//! Reflectance Profiles for Efficient Subsurface Scattering", Pixar
//! Technical Memo 15-04): a second skin profile beside the six Gaussians,
//! parameterised as the engines do, its exact sampling, its 1D marginal
//! (what a separable pass and the flat card see) and the card's closed form.
//!
//! # The profile
//!
//! Per channel, with surface albedo `A` and scaling factor `s` (1/mm),
//!
//! `R(r) = A s (e^(-s r) + e^(-s r / 3)) / (8 pi r)`,
//!
//! whose integral over the plane is `A`: `integral_0^inf 2 pi r R(r) dr =
//! (A s / 4) (1/s + 3/s)`. `s = fit(A) / l`, where `l` is a length the
//! artist sets (a mean free path or the diffuse mean free path, per fit)
//! and `fit` one of the paper's three fits of `s l` to the albedo ([`SFit`]).
//!
//! # Sampling the radius
//!
//! `p(r) = 2 pi r R(r) / A = s (e^(-s r) + e^(-s r / 3)) / 4` is a
//! mixture of two exponentials (weights 1/4 and 3/4, means `1/s` and `3/s`),
//! so `F(r) = 1 - e^(-s r) / 4 - 3 e^(-s r / 3) / 4` and the mean radius is
//! `E[r] = (1/4)(1/s) + (3/4)(3/s) = 2.5 / s`. Its inverse is exact: with
//! `u = e^(-s r / 3)`, `1 - F = u^3 / 4 + 3 u / 4`, a depressed cubic
//! `u^3 + 3u - 4g = 0` (`g = 1 - F`) with one real root; Cardano's formula
//! in its hyperbolic form gives `u = 2 sinh(asinh(2g) / 3)`, and
//! `r = -3 ln(u) / s` ([`radial_inverse_cdf`]).
//!
//! # The marginal and the card
//!
//! Integrated across a line, `integral e^(-k sqrt(x^2 + y^2)) /
//! sqrt(x^2 + y^2) dy = 2 K0(k |x|)` (modified Bessel function), so
//!
//! `m(x) = A s / (4 pi) [K0(s |x|) + K0(s |x| / 3)]`,
//!
//! which integrates to `A` since `integral_0^inf K0 = pi / 2`. The card (see
//! [`super::card`]: albedo `a_L` left of the edge and `a_R` right of it,
//! applied before scattering, profile normalised to `A = 1`) then shows
//! `M(x) = a_L T(x) + a_R (1 - T(x))` under unit irradiance, with the tail
//! `T(x) = integral_x^inf m / A = [Ki1(s x) + 3 Ki1(s x / 3)] / (4 pi)` for
//! `x >= 0` (`T(-x) = 1 - T(x)`), where `Ki1(z) = integral_z^inf K0` is the
//! Bickley-Naylor function. The marginal's first moment over a cell uses
//! `integral t K0(t) dt = -t K1(t)`.
//!
//! # Moments, and matching the six Gaussians
//!
//! For any radial profile, the projection of a radius `r` on a line has
//! `E|x| = (2 / pi) r`, so the energy an edge moves (the first absolute
//! moment the card measures, `integral_0^inf T`) is `E[x^+] = E[r] / pi`:
//! `2.5 / (pi s)` here, and `sum_i w_i sigma_i / sqrt(2 pi)` for the six
//! Gaussians (the mean radius of a 2D Gaussian of per-axis variance `v` is
//! `sqrt(pi v / 2)`). Matching the mean radius therefore matches the edge
//! spread exactly; the two are one match, not two. The marginal's variance
//! is `E[r^2] / 2 = 7 / s^2` (`E[r^2] = 14 / s^2`); matching that instead
//! weighs the far tail, and Burley's exponential tail is longer than the
//! Gaussians' (see [`SkinMatch`]).
//!
//! Table 4.2's weights sum to 1 in every channel (d'Eon's profile is
//! normalised to white; the albedo map carries the colour), so matching its
//! total reflectance gives `A = 1`, the top of the fits' range. The albedo
//! enters the scattered shape only through `s`; with `s` set by the mean
//! radius, `A` decides only the length `l = fit(A) / s` an engine would be
//! given ([`BurleyParams::matching_six_gaussians_with_albedo`] takes the
//! skin's own albedo instead).
//!
//! # Numerics
//!
//! `K0`, `K1` and `Ki1` come from their integral representations
//! `integral_0^inf e^(-z cosh u) cosh(u)^k du` (k = 0, 1, -1) evaluated by
//! the trapezoidal rule, which converges geometrically for integrands
//! analytic in a strip (here `|Im u| < pi / 2`): within 1e-13 relative of
//! mpmath for `1e-6 <= z <= 600` (the tests' bound), below which the
//! leading terms of the small-argument series are exact to rounding. No polynomial fit (A&S
//! 9.8.5/9.8.6 are good to ~1e-7), so tests can hold quadrature to 1e-9.

use std::f64::consts::PI;

use anyhow::{bail, Result};

use super::profile::{SIX_GAUSSIAN_VARIANCES_MM2, SIX_GAUSSIAN_WEIGHTS_RGB};

const CHANNELS: [&str; 3] = ["red", "green", "blue"];

/// Euler-Mascheroni constant.
const EULER_GAMMA: f64 = 0.577_215_664_901_532_9;

/// The published fits of `s l` (scaling factor times a length) to the
/// surface albedo `A`, all from Christensen & Burley 2015, section 5.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub enum SFit {
    /// Searchlight configuration, `l` the mean free path:
    /// `s l = 1.85 - A + 7 |A - 0.8|^3`.
    Searchlight,
    /// Diffuse surface transmission, `l` the mean free path:
    /// `s l = 1.9 - A + 3.5 (A - 0.8)^2`.
    DiffuseTransmission,
    /// Searchlight configuration, `l` the diffuse mean free path:
    /// `s l = 3.5 + 100 (A - 0.33)^4`. Unreal's
    /// `BurleyNormalizedSSSCommon.ush` uses this one (its artists set a
    /// mean free path colour and distance), hence the default.
    #[default]
    DiffuseMeanFreePath,
}

impl SFit {
    /// Every fit, for listings and exhaustive tests.
    pub const ALL: [SFit; 3] = [
        SFit::Searchlight,
        SFit::DiffuseTransmission,
        SFit::DiffuseMeanFreePath,
    ];

    /// Short name.
    pub fn name(self) -> &'static str {
        match self {
            SFit::Searchlight => "searchlight",
            SFit::DiffuseTransmission => "diffuse-transmission",
            SFit::DiffuseMeanFreePath => "dmfp",
        }
    }

    /// Where the fit is published (and used).
    pub fn source(self) -> &'static str {
        match self {
            SFit::Searchlight | SFit::DiffuseTransmission => {
                "Christensen & Burley 2015, Pixar tech memo 15-04"
            }
            SFit::DiffuseMeanFreePath => {
                "Christensen & Burley 2015, Pixar tech memo 15-04; \
                 Unreal BurleyNormalizedSSSCommon.ush"
            }
        }
    }

    /// Which length `l` the fit scales: the mean free path or the diffuse
    /// mean free path.
    pub fn length(self) -> &'static str {
        match self {
            SFit::Searchlight | SFit::DiffuseTransmission => "mean free path",
            SFit::DiffuseMeanFreePath => "diffuse mean free path",
        }
    }

    /// `s l` at albedo `a`.
    pub fn s_times_length(self, a: f64) -> f64 {
        match self {
            SFit::Searchlight => 1.85 - a + 7.0 * (a - 0.8).abs().powi(3),
            SFit::DiffuseTransmission => 1.9 - a + 3.5 * (a - 0.8).powi(2),
            SFit::DiffuseMeanFreePath => 3.5 + 100.0 * (a - 0.33).powi(4),
        }
    }
}

/// What [`BurleyParams::matching_six_gaussians_by`] keeps equal per
/// channel between Burley's profile and the six Gaussians.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SkinMatch {
    /// The mean radius `E[r]`, and with it the energy an edge moves
    /// (`E[r] / pi` for any radial profile): what the card measures and
    /// what decides how far colour bleeds over a boundary.
    #[default]
    MeanRadius,
    /// The marginal's variance (`7 / s^2` against `sum_i w_i v_i`): weighs
    /// the faint far tail, so Burley's long exponential tail makes it
    /// narrower near the centre.
    MarginalVariance,
}

/// Burley's profile per RGB channel, as engines parameterise it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BurleyParams {
    /// Surface albedo `A` (the profile's total reflectance), in (0, 1].
    pub albedo: [f64; 3],
    /// The length `l` the fit scales (mm): the mean free path or the
    /// diffuse mean free path, as [`SFit::length`] says.
    pub mfp_mm: [f64; 3],
    /// The fit of `s l` to the albedo.
    pub fit: SFit,
}

impl BurleyParams {
    /// Checks ranges so that `s` is finite and positive.
    pub fn validate(&self) -> Result<()> {
        let channels = CHANNELS.iter().zip(&self.albedo).zip(&self.mfp_mm);
        for ((name, &a), &l) in channels {
            if !a.is_finite() || a <= 0.0 || a > 1.0 {
                bail!("Burley albedo ({name}) must be a finite value in (0, 1], got {a}");
            }
            if !l.is_finite() || l <= 0.0 {
                bail!(
                    "Burley {} ({name}) must be finite and > 0 mm, got {l}",
                    self.fit.length()
                );
            }
        }
        Ok(())
    }

    /// The parameters whose scaling factor is `s` (1/mm) at albedo `albedo`.
    pub fn from_s(albedo: [f64; 3], s: [f64; 3], fit: SFit) -> Self {
        let mfp_mm = std::array::from_fn(|c| fit.s_times_length(albedo[c]) / s[c]);
        Self {
            albedo,
            mfp_mm,
            fit,
        }
    }

    /// Burley matched to the six-Gaussian skin by [`SkinMatch::MeanRadius`]
    /// (the default; see the module docs), `A` = Table 4.2's total (1).
    pub fn matching_six_gaussians(fit: SFit) -> Self {
        Self::matching_six_gaussians_by(fit, SkinMatch::MeanRadius)
    }

    /// Burley matched to the six-Gaussian skin: `A` per channel is the
    /// channel's weight sum, `s` keeps `by` equal.
    pub fn matching_six_gaussians_by(fit: SFit, by: SkinMatch) -> Self {
        // The f32 weights sum to 1 only to ~1e-7; above 1 is rounding.
        let albedo = six_gaussian_reflectance().map(|a| a.min(1.0));
        Self::matching_six_gaussians_with_albedo(fit, by, albedo)
    }

    /// The six-Gaussian skin's shape (`s` by `by`) with the surface albedo
    /// `albedo` instead of the profile's normalised total: the length an
    /// engine needs for that skin colour.
    pub fn matching_six_gaussians_with_albedo(fit: SFit, by: SkinMatch, albedo: [f64; 3]) -> Self {
        let s = match by {
            SkinMatch::MeanRadius => six_gaussian_mean_radius_mm().map(|r| 2.5 / r),
            SkinMatch::MarginalVariance => {
                six_gaussian_marginal_variance_mm2().map(|v| (7.0 / v).sqrt())
            }
        };
        Self::from_s(albedo, s, fit)
    }

    /// Scaling factor `s = fit(A) / l` per channel (1/mm).
    pub fn s(&self) -> [f64; 3] {
        std::array::from_fn(|c| self.fit.s_times_length(self.albedo[c]) / self.mfp_mm[c])
    }

    /// Mean radius `E[r] = 2.5 / s` per channel (mm).
    pub fn mean_radius_mm(&self) -> [f64; 3] {
        self.s().map(|s| 2.5 / s)
    }

    /// The marginal's variance `7 / s^2` per channel (mm^2).
    pub fn marginal_variance_mm2(&self) -> [f64; 3] {
        self.s().map(|s| 7.0 / (s * s))
    }

    /// `R(r)` per channel (per mm^2), albedo included.
    pub fn profile(&self, r_mm: f64) -> [f64; 3] {
        let s = self.s();
        std::array::from_fn(|c| self.albedo[c] * radial_pdf(s[c], r_mm) / (2.0 * PI * r_mm))
    }

    /// The marginal `m(x)` per channel (per mm), albedo included.
    pub fn marginal(&self, x_mm: f64) -> [f64; 3] {
        let s = self.s();
        std::array::from_fn(|c| self.albedo[c] * marginal_pdf(s[c], x_mm))
    }

    /// The card's exitance at `x` under unit irradiance with albedo `a_l`
    /// left of the edge and `a_r` right of it (applied before scattering,
    /// profile normalised to 1, as [`super::card::Card::exitance`]).
    pub fn edge_response(&self, x_mm: f64, a_l: [f64; 3], a_r: [f64; 3]) -> [f64; 3] {
        let s = self.s();
        std::array::from_fn(|c| {
            let left = marginal_tail(s[c], x_mm);
            a_l[c] * left + a_r[c] * (1.0 - left)
        })
    }

    /// Energy moved across an edge of unit contrast under unit irradiance,
    /// per channel (mm): `integral_0^inf T = E[r] / pi = 2.5 / (pi s)`.
    pub fn edge_spread_mm(&self) -> [f64; 3] {
        self.s().map(|s| 2.5 / (PI * s))
    }
}

/// Per-channel total reflectance of the six-Gaussian profile, `sum_i w_i`.
pub fn six_gaussian_reflectance() -> [f64; 3] {
    let mut out = [0.0; 3];
    for w in &SIX_GAUSSIAN_WEIGHTS_RGB {
        for c in 0..3 {
            out[c] += f64::from(w[c]);
        }
    }
    out
}

/// Per-channel mean radius of the six-Gaussian profile (mm):
/// `sum_i w_i sqrt(pi v_i / 2) / sum_i w_i`.
pub fn six_gaussian_mean_radius_mm() -> [f64; 3] {
    let total = six_gaussian_reflectance();
    let mut out = [0.0; 3];
    for (&v, w) in SIX_GAUSSIAN_VARIANCES_MM2
        .iter()
        .zip(SIX_GAUSSIAN_WEIGHTS_RGB.iter())
    {
        let mean = (PI * f64::from(v) / 2.0).sqrt();
        for c in 0..3 {
            out[c] += f64::from(w[c]) * mean / total[c];
        }
    }
    out
}

/// Per-channel variance of the six-Gaussian marginal (mm^2), normalised:
/// `sum_i w_i v_i / sum_i w_i`.
pub fn six_gaussian_marginal_variance_mm2() -> [f64; 3] {
    let total = six_gaussian_reflectance();
    let mut out = [0.0; 3];
    for (&v, w) in SIX_GAUSSIAN_VARIANCES_MM2
        .iter()
        .zip(SIX_GAUSSIAN_WEIGHTS_RGB.iter())
    {
        for c in 0..3 {
            out[c] += f64::from(w[c]) * f64::from(v) / total[c];
        }
    }
    out
}

/// Radial pdf `p(r) = s (e^(-s r) + e^(-s r / 3)) / 4` (per mm).
pub fn radial_pdf(s: f64, r_mm: f64) -> f64 {
    s * ((-s * r_mm).exp() + (-s * r_mm / 3.0).exp()) / 4.0
}

/// Radial CDF `F(r) = 1 - e^(-s r) / 4 - 3 e^(-s r / 3) / 4`.
pub fn radial_cdf(s: f64, r_mm: f64) -> f64 {
    1.0 - (-s * r_mm).exp() / 4.0 - 0.75 * (-s * r_mm / 3.0).exp()
}

/// `1 - F(r) = e^(-s r) / 4 + 3 e^(-s r / 3) / 4`, without the
/// cancellation of `1 - F` far out.
pub fn radial_tail(s: f64, r_mm: f64) -> f64 {
    (-s * r_mm).exp() / 4.0 + 0.75 * (-s * r_mm / 3.0).exp()
}

/// The radius whose CDF is `f` (in [0, 1]); infinite at `f = 1`. Near 1
/// the radius is ill-conditioned in `f`: sample with
/// [`radial_inverse_tail`] of a uniform instead (the same distribution).
pub fn radial_inverse_cdf(s: f64, f: f64) -> f64 {
    radial_inverse_tail(s, 1.0 - f)
}

/// The radius whose tail `1 - F` is `g` (in [0, 1]): `r = -3 ln(u) / s`
/// with `u = 2 sinh(asinh(2 g) / 3)`, the real root of `u^3 + 3u = 4g`
/// (see the module docs). Full relative precision as `g -> 0`.
pub fn radial_inverse_tail(s: f64, g: f64) -> f64 {
    let u = 2.0 * ((2.0 * g).asinh() / 3.0).sinh();
    // u <= 1 up to rounding; r is never negative.
    (-3.0 * u.ln() / s).max(0.0)
}

/// The normalised marginal `s / (4 pi) [K0(s |x|) + K0(s |x| / 3)]` (per
/// mm; infinite at `x = 0`, a log singularity that integrates).
pub fn marginal_pdf(s: f64, x_mm: f64) -> f64 {
    let z = s * x_mm.abs();
    s / (4.0 * PI) * (bessel_k0(z) + bessel_k0(z / 3.0))
}

/// `P(X > x)` under the normalised marginal, any `x`:
/// `[Ki1(s x) + 3 Ki1(s x / 3)] / (4 pi)` for `x >= 0`.
pub fn marginal_tail(s: f64, x_mm: f64) -> f64 {
    let z = s * x_mm.abs();
    let t = (bickley_ki1(z) + 3.0 * bickley_ki1(z / 3.0)) / (4.0 * PI);
    if x_mm >= 0.0 {
        t
    } else {
        1.0 - t
    }
}

/// Mass of the normalised marginal on `[a, b]` (negative when `b < a`).
pub fn marginal_integral(s: f64, a_mm: f64, b_mm: f64) -> f64 {
    marginal_tail(s, a_mm) - marginal_tail(s, b_mm)
}

/// `integral_a^b x m(x) dx` of the normalised marginal: with `G(y) =
/// integral_y^inf x m = [z K1(z) + 9 (z/3) K1(z/3)] / (4 pi s)` at
/// `z = s y` (from `integral t K0(t) dt = -t K1(t)`) and `x m(x)` odd, the
/// antiderivative is `-G(|x|)`.
pub fn marginal_first_moment(s: f64, a_mm: f64, b_mm: f64) -> f64 {
    let g = |x: f64| {
        let z = s * x.abs();
        (z_bessel_k1(z) + 9.0 * z_bessel_k1(z / 3.0)) / (4.0 * PI * s)
    };
    g(a_mm) - g(b_mm)
}

/// The half-width (mm) within which the normalised marginal keeps the
/// fraction `p` (in (0, 1)) of its mass: `T(x) = (1 - p) / 2`, by bisection.
pub fn marginal_quantile_half_width(s: f64, p: f64) -> f64 {
    let target = 0.5 * (1.0 - p);
    let (mut lo, mut hi) = (0.0, 1.0 / s);
    while marginal_tail(s, hi) > target {
        hi *= 2.0;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if marginal_tail(s, mid) > target {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo <= 1e-15 * hi {
            break;
        }
    }
    0.5 * (lo + hi)
}

/// Below this argument the Bessel functions use their small-argument series.
const SMALL_Z: f64 = 1e-6;

/// Above this argument `e^(-z)` underflows: every function here is 0.
const LARGE_Z: f64 = 746.0;

/// `integral_0^inf e^(-z (cosh u - 1)) cosh(u)^k du` for `k` in {-1, 0, 1}
/// and `z >= SMALL_Z`, by the trapezoidal rule (exponentially convergent for
/// this analytic integrand). The step shrinks as `1/sqrt(z)` for large `z`,
/// where the integrand is a Gaussian of width `1/sqrt(z)` in `u`.
fn scaled_cosh_integral(z: f64, k: i32) -> f64 {
    let h = (0.5 / z.sqrt()).min(0.2);
    let mut sum = 0.5; // the u = 0 node, halved
    for j in 1..100_000 {
        let u = f64::from(j) * h;
        let c = u.cosh();
        // cosh u - 1 = 2 sinh^2(u/2), without cancellation near u = 0.
        let e = 2.0 * (0.5 * u).sinh().powi(2) * z;
        let term = (-e).exp() * c.powi(k);
        sum += term;
        // Past the peak (only k = 1 rises first) and negligible: done.
        if (k <= 0 || z * c > 1.0) && term < 1e-18 * sum {
            break;
        }
    }
    sum * h
}

/// Modified Bessel function of the second kind `K0(z)`, `z > 0`
/// (infinite at 0).
pub fn bessel_k0(z: f64) -> f64 {
    if z <= 0.0 {
        return f64::INFINITY;
    }
    if z > LARGE_Z {
        return 0.0;
    }
    if z < SMALL_Z {
        // K0 = -(ln(z/2) + gamma) I0(z) + z^2/4 + O(z^4 ln z).
        let l = (0.5 * z).ln() + EULER_GAMMA;
        return -l * (1.0 + 0.25 * z * z) + 0.25 * z * z;
    }
    (-z).exp() * scaled_cosh_integral(z, 0)
}

/// `K1(z)`, `z > 0` (infinite at 0).
pub fn bessel_k1(z: f64) -> f64 {
    if z <= 0.0 {
        return f64::INFINITY;
    }
    z_bessel_k1(z) / z
}

/// `z K1(z)`, continuous at 0 where it is 1.
fn z_bessel_k1(z: f64) -> f64 {
    if z > LARGE_Z {
        return 0.0;
    }
    if z < SMALL_Z {
        // z K1(z) = 1 + (z^2 / 2)(ln(z/2) + gamma - 1/2) + O(z^4 ln z).
        if z <= 0.0 {
            return 1.0;
        }
        return 1.0 + 0.5 * z * z * ((0.5 * z).ln() + EULER_GAMMA - 0.5);
    }
    z * (-z).exp() * scaled_cosh_integral(z, 1)
}

/// Bickley-Naylor function `Ki1(z) = integral_z^inf K0(t) dt`, `z >= 0`
/// (`pi / 2` at 0).
pub fn bickley_ki1(z: f64) -> f64 {
    if z > LARGE_Z {
        return 0.0;
    }
    if z < SMALL_Z {
        // integral_0^z K0 = z (1 - gamma - ln(z/2)) + O(z^3 ln z).
        if z <= 0.0 {
            return 0.5 * PI;
        }
        return 0.5 * PI - z * (1.0 - EULER_GAMMA - (0.5 * z).ln());
    }
    (-z).exp() * scaled_cosh_integral(z, -1)
}

#[cfg(test)]
#[path = "burley_tests.rs"]
mod tests;
