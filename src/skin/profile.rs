//! d'Eon et al.'s sum-of-Gaussians fit of the three-layer skin diffusion
//! profile (Jimenez's thesis, Table 4.2), plus the error function needed to
//! integrate it exactly along a line.
//!
//! Why exact integrals: the narrowest Gaussian has a variance of only
//! 0.0064 mm^2 (sigma = 0.08 mm). Point-sampling the profile at a handful of
//! kernel taps would either miss that spike or overweight it, depending on
//! where the taps land. Integrating each Gaussian over a kernel cell with
//! `erf` is exact for any cell size.

use std::f64::consts::PI;

/// The six-Gaussian skin fit of Table 4.2: variances (mm^2) and RGB weights,
/// written once for Rust and the shaders (lighting.glsl's transmittance, the
/// ground truth's passes) in `crate::shader_constants`.
pub use crate::shader_constants::{SIX_GAUSSIAN_VARIANCES_MM2, SIX_GAUSSIAN_WEIGHTS_RGB};

/// Variances (mm^2) of the four-Gaussian skin fit, Table 4.2.
pub const FOUR_GAUSSIAN_VARIANCES_MM2: [f32; 4] = [0.0064, 0.0516, 0.2719, 2.0062];

/// Weights `w_i` (rows: one Gaussian; columns: R, G, B) of the four-Gaussian
/// skin fit, Table 4.2 (the original weights, not the blended `w'_i`).
pub const FOUR_GAUSSIAN_WEIGHTS_RGB: [[f32; 3]; 4] = [
    [0.2405, 0.4474, 0.6157],
    [0.1158, 0.3661, 0.3439],
    [0.1836, 0.1864, 0.0],
    [0.46, 0.0, 0.0402],
];

/// Normalised 2D Gaussian `G(v, r) = exp(-r^2 / (2v)) / (2 pi v)`.
///
/// d'Eon's convention: the integral over the whole plane is 1, so the fit
/// weights directly give each Gaussian's share of the diffuse response.
pub fn gaussian_2d(variance: f64, r: f64) -> f64 {
    (-r * r / (2.0 * variance)).exp() / (2.0 * PI * variance)
}

/// Red channel of the six-Gaussian skin profile `R(r)` (r in mm).
///
/// The separable kernel (eq. 6.1) uses this single curve as its base
/// profile `p[x]` for all three channels, reshaped per channel by falloff.
pub fn red_profile(r_mm: f64) -> f64 {
    SIX_GAUSSIAN_VARIANCES_MM2
        .iter()
        .zip(SIX_GAUSSIAN_WEIGHTS_RGB.iter())
        .map(|(&v, w)| f64::from(w[0]) * gaussian_2d(f64::from(v), r_mm))
        .sum()
}

/// Exact `integral_{a}^{b} red_profile(|x|) dx` along a straight line (mm).
///
/// For one Gaussian, `integral exp(-x^2/(2v)) / (2 pi v) dx` over `[a, b]`
/// equals `(Phi(b/sigma) - Phi(a/sigma)) / sqrt(2 pi v)` with
/// `sigma = sqrt(v)`, i.e. `(erf(b/sqrt(2v)) - erf(a/sqrt(2v))) / (2 sqrt(2 pi v))`.
/// (The line integral of the 2D-normalised Gaussian is `1/sqrt(2 pi v)`,
/// not 1.) The result is negative when `b < a`.
pub fn red_profile_line_integral(a_mm: f64, b_mm: f64) -> f64 {
    SIX_GAUSSIAN_VARIANCES_MM2
        .iter()
        .zip(SIX_GAUSSIAN_WEIGHTS_RGB.iter())
        .map(|(&v, w)| f64::from(w[0]) * gaussian_line_integral(f64::from(v), a_mm, b_mm))
        .sum()
}

/// Line integral of one 2D-normalised Gaussian over `[a, b]`.
fn gaussian_line_integral(variance: f64, a: f64, b: f64) -> f64 {
    gaussian_marginal_integral(variance, a, b) / (2.0 * PI * variance).sqrt()
}

/// `Phi(b/sigma) - Phi(a/sigma)` with `sigma = sqrt(variance)`: the mass of
/// the 1D Gaussian (the 2D Gaussian's marginal) on `[a, b]`.
fn gaussian_marginal_integral(variance: f64, a: f64, b: f64) -> f64 {
    let s = (2.0 * variance).sqrt();
    let (za, zb) = (a / s, b / s);
    // Subtract tails rather than erf values when the interval lies on one
    // side of zero: keeps full relative precision for cells far out in the
    // tail, where erf(za) and erf(zb) are both ~1.
    let diff = if za >= 0.0 {
        erfc(za) - erfc(zb)
    } else if zb <= 0.0 {
        erfc(-zb) - erfc(-za)
    } else {
        erf(zb) - erf(za)
    };
    0.5 * diff
}

/// The six-Gaussian profile `R_c(r)` of every channel (r in mm, per mm^2).
pub fn profile_rgb(r_mm: f64) -> [f64; 3] {
    let mut out = [0.0; 3];
    for (&v, w) in SIX_GAUSSIAN_VARIANCES_MM2
        .iter()
        .zip(SIX_GAUSSIAN_WEIGHTS_RGB.iter())
    {
        let g = gaussian_2d(f64::from(v), r_mm);
        for c in 0..3 {
            out[c] += f64::from(w[c]) * g;
        }
    }
    out
}

/// Exact `integral_a^b m_c(x) dx` of the profile's marginal (mm) for channel
/// `c`: `m_c(x) = integral R_c(sqrt(x^2 + y^2)) dy = sum_i w_ic N(x; 0, v_i)`,
/// the 2D profile projected onto a line (each 2D Gaussian's marginal is the
/// 1D Gaussian of the same variance). Integrates to 1 over the whole line,
/// unlike [`red_profile_line_integral`] (a slice through the centre, which
/// weighs Gaussian i by `w_i / sqrt(2 pi v_i)`). Negative when `b < a`.
pub fn marginal_integral(c: usize, a_mm: f64, b_mm: f64) -> f64 {
    SIX_GAUSSIAN_VARIANCES_MM2
        .iter()
        .zip(SIX_GAUSSIAN_WEIGHTS_RGB.iter())
        .map(|(&v, w)| f64::from(w[c]) * gaussian_marginal_integral(f64::from(v), a_mm, b_mm))
        .sum()
}

/// Exact `integral_a^b x m_c(x) dx` (the marginal's first moment over
/// `[a, b]`): per Gaussian `sigma (phi(a/sigma) - phi(b/sigma))`, i.e.
/// `sqrt(v / 2 pi) (exp(-a^2/2v) - exp(-b^2/2v))`.
pub fn marginal_first_moment(c: usize, a_mm: f64, b_mm: f64) -> f64 {
    SIX_GAUSSIAN_VARIANCES_MM2
        .iter()
        .zip(SIX_GAUSSIAN_WEIGHTS_RGB.iter())
        .map(|(&v, w)| {
            let v = f64::from(v);
            let e = |x: f64| (-x * x / (2.0 * v)).exp();
            f64::from(w[c]) * (v / (2.0 * PI)).sqrt() * (e(a_mm) - e(b_mm))
        })
        .sum()
}

/// Per-channel variance of the profile along one axis, `sum_i w_ic v_i`
/// (mm^2): the variance of its marginal.
pub fn profile_variance_mm2() -> [f64; 3] {
    let mut out = [0.0; 3];
    for (&v, w) in SIX_GAUSSIAN_VARIANCES_MM2
        .iter()
        .zip(SIX_GAUSSIAN_WEIGHTS_RGB.iter())
    {
        for c in 0..3 {
            out[c] += f64::from(w[c]) * f64::from(v);
        }
    }
    out
}

/// Standard normal distribution function `Phi(x) = erfc(-x / sqrt 2) / 2`.
pub fn normal_cdf(x: f64) -> f64 {
    0.5 * erfc(-x / std::f64::consts::SQRT_2)
}

/// Below this |x| the power series is used; above it the continued fraction.
const SERIES_LIMIT: f64 = 2.5;

/// Error function, accurate to a few ulp (~1e-15 absolute) for all x.
///
/// Uses the everywhere-positive series
/// `erf(x) = 2/sqrt(pi) exp(-x^2) sum_n (2x^2)^n x / (1*3*...*(2n+1))`
/// (no cancellation, unlike the alternating Taylor series) for small |x|,
/// and `1 - erfc` via a continued fraction for large |x|.
pub fn erf(x: f64) -> f64 {
    if x.is_nan() {
        return f64::NAN;
    }
    let ax = x.abs();
    let r = if ax < SERIES_LIMIT {
        erf_series(ax)
    } else {
        1.0 - erfc_continued_fraction(ax)
    };
    r.copysign(x)
}

/// Complementary error function `1 - erf(x)`, with full relative precision
/// in the right tail (where `1 - erf(x)` would cancel).
pub fn erfc(x: f64) -> f64 {
    if x.is_nan() {
        return f64::NAN;
    }
    if x < 0.0 {
        2.0 - erfc(-x)
    } else if x < SERIES_LIMIT {
        1.0 - erf_series(x)
    } else {
        erfc_continued_fraction(x)
    }
}

/// `erf(x)` for `0 <= x < SERIES_LIMIT` by the positive series.
fn erf_series(x: f64) -> f64 {
    let x2 = x * x;
    let mut term = x;
    let mut sum = x;
    for n in 1..200 {
        term *= 2.0 * x2 / f64::from(2 * n + 1);
        sum += term;
        if term <= sum * 1e-17 {
            break;
        }
    }
    2.0 / PI.sqrt() * (-x2).exp() * sum
}

/// `erfc(x)` for `x >= SERIES_LIMIT` by the Laplace continued fraction
/// `erfc(x) = exp(-x^2)/sqrt(pi) / (x + (1/2)/(x + 1/(x + (3/2)/(x + ...))))`,
/// evaluated with the modified Lentz algorithm. All partial terms are
/// positive, so no tiny-denominator guard is needed.
fn erfc_continued_fraction(x: f64) -> f64 {
    if x > 27.0 {
        // exp(-x^2) underflows to zero anyway.
        return 0.0;
    }
    let mut f = x;
    let mut c = x;
    let mut d = 0.0;
    for k in 1..1000 {
        let a = f64::from(k) * 0.5;
        d = 1.0 / (x + a * d);
        c = x + a / c;
        let delta = c * d;
        f *= delta;
        if (delta - 1.0).abs() < 1e-16 {
            break;
        }
    }
    (-x * x).exp() / PI.sqrt() / f
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Reference values from standard tables (Abramowitz & Stegun / mpmath).
    const ERF_TABLE: [(f64, f64); 8] = [
        (0.1, 0.112_462_916_018_284_9),
        (0.5, 0.520_499_877_813_046_5),
        (1.0, 0.842_700_792_949_714_9),
        (1.5, 0.966_105_146_475_310_7),
        (2.0, 0.995_322_265_018_952_7),
        (2.5, 0.999_593_047_982_555),
        (3.0, 0.999_977_909_503_001_4),
        (4.0, 0.999_999_984_582_742_1),
    ];

    #[test]
    fn erf_matches_reference_values() {
        for &(x, want) in &ERF_TABLE {
            assert!((erf(x) - want).abs() < 1e-14, "erf({x}) = {}", erf(x));
            assert!((erf(-x) + want).abs() < 1e-14, "erf(-{x})");
        }
        assert_eq!(erf(0.0), 0.0);
        assert_eq!(erf(40.0), 1.0);
        assert!(erf(f64::NAN).is_nan());
    }

    #[test]
    fn erfc_keeps_relative_precision_in_the_tail() {
        // erfc(3) = 2.209049699858544e-5, erfc(5) = 1.5374597944280349e-12,
        // erfc(2) = 4.677734981047266e-3.
        let cases = [
            (2.0, 4.677_734_981_047_266e-3),
            (3.0, 2.209_049_699_858_544e-5),
            (5.0, 1.537_459_794_428_035e-12),
        ];
        for (x, want) in cases {
            let rel = (erfc(x) - want).abs() / want;
            assert!(rel < 1e-12, "erfc({x}) rel err {rel}");
        }
        assert!((erfc(-1.0) - (1.0 + ERF_TABLE[2].1)).abs() < 1e-15);
    }

    #[test]
    fn erf_is_continuous_at_the_method_switch() {
        let below = erf(SERIES_LIMIT - 1e-12);
        let above = erf(SERIES_LIMIT);
        assert!((below - above).abs() < 1e-14);
    }

    #[test]
    fn six_gaussian_channels_have_unit_response() {
        for c in 0..3 {
            let s: f32 = SIX_GAUSSIAN_WEIGHTS_RGB.iter().map(|w| w[c]).sum();
            assert!((s - 1.0).abs() < 1e-6, "channel {c} sums to {s}");
        }
    }

    #[test]
    fn red_profile_has_unit_2d_integral() {
        // integral_0^inf 2 pi r R(r) dr by the midpoint rule on [0, 40] mm.
        let n = 400_000;
        let h = 40.0 / f64::from(n);
        let total: f64 = (0..n)
            .map(|i| {
                let r = (f64::from(i) + 0.5) * h;
                2.0 * PI * r * red_profile(r) * h
            })
            .sum();
        assert!((total - 1.0).abs() < 1e-6, "total {total}");
    }

    #[test]
    fn line_integral_matches_simpson() {
        let simpson = |a: f64, b: f64| {
            let n = 20_000;
            let h = (b - a) / f64::from(n);
            let mut s = red_profile(a.abs()) + red_profile(b.abs());
            for i in 1..n {
                let w = if i % 2 == 1 { 4.0 } else { 2.0 };
                s += w * red_profile((a + f64::from(i) * h).abs());
            }
            s * h / 3.0
        };
        for (a, b) in [
            (-1.0, 2.0),
            (0.0, 0.05),
            (0.3, 4.0),
            (-6.0, -5.0),
            (-0.01, 0.02),
        ] {
            let exact = red_profile_line_integral(a, b);
            let num = simpson(a, b);
            assert!(
                (exact - num).abs() <= 1e-10 * num.abs().max(1e-12),
                "[{a},{b}]: {exact} vs {num}"
            );
        }
        // Whole line: sum_i w_i / sqrt(2 pi v_i).
        let whole: f64 = SIX_GAUSSIAN_VARIANCES_MM2
            .iter()
            .zip(SIX_GAUSSIAN_WEIGHTS_RGB.iter())
            .map(|(&v, w)| f64::from(w[0]) / (2.0 * PI * f64::from(v)).sqrt())
            .sum();
        assert!((red_profile_line_integral(-100.0, 100.0) - whole).abs() < 1e-13);
        assert!(
            (red_profile_line_integral(2.0, 1.0) + red_profile_line_integral(1.0, 2.0)).abs()
                < 1e-16
        );
    }

    #[test]
    fn gaussian_2d_peak() {
        assert!((gaussian_2d(1.0, 0.0) - 1.0 / (2.0 * PI)).abs() < 1e-15);
    }
}
