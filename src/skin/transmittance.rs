//! Transmittance through thin skin (Jimenez's thesis, section 5.4-5.5).
//!
//! Assuming the irradiance behind a thin slab is locally constant, the
//! convolution with the sum-of-Gaussians profile collapses to a function of
//! the distance travelled inside the object only (eq. 5.12):
//! `T(s) = sum_i w_i exp(-s^2 / v_i)`.

use super::kernel::DEMO_UNIT_MM;
use super::profile::{SIX_GAUSSIAN_VARIANCES_MM2, SIX_GAUSSIAN_WEIGHTS_RGB};

/// `T(s)` of eq. 5.12 for a path length `s_mm` (mm) inside the skin, using
/// the six-Gaussian weights and variances (mm^2) of Table 4.2 / Listing 5.1.
/// `T(0)` is the sum of the weights, i.e. (1, 1, 1).
pub fn transmittance_rgb(s_mm: f32) -> [f32; 3] {
    transmittance_rgb_with(s_mm, TransmittanceProfile::Thesis)
}

/// Which T(s) the geometry pass uses.
///
/// The thesis' eq. 5.12 is T(s) = sum_i w_i exp(-s^2 / v_i). Integrating d'Eon's
/// profile, with G(v, r) = exp(-r^2 / 2v) / (2 pi v) as in eq. 5.3, over a plane at
/// distance d gives sum_i w_i exp(-d^2 / (2 v_i)) instead (the step from eq. 5.9 to
/// 5.10 drops the 2). That is the same function at s / sqrt(2). `Thesis` is
/// the default, since it is the published method; `Integral` is the consistent one.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, clap::ValueEnum,
)]
#[serde(rename_all = "kebab-case")]
pub enum TransmittanceProfile {
    /// Eq. 5.12 as published.
    #[value(alias = "eq5.12")]
    Thesis,
    /// The profile integrated over a plane: exp(-s^2 / 2v) (docs/accuracy.md).
    Integral,
}

impl std::str::FromStr for TransmittanceProfile {
    type Err = anyhow::Error;
    fn from_str(s: &str) -> anyhow::Result<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "thesis" | "eq5.12" => Ok(TransmittanceProfile::Thesis),
            "integral" => Ok(TransmittanceProfile::Integral),
            other => {
                anyhow::bail!("unknown transmittance profile '{other}' (valid: thesis, integral)")
            }
        }
    }
}

impl TransmittanceProfile {
    /// The factor k in exp(-k s^2 / v): 1 for eq. 5.12, 1/2 for the integral.
    pub fn exponent_scale(self) -> f32 {
        match self {
            TransmittanceProfile::Thesis => 1.0,
            TransmittanceProfile::Integral => 0.5,
        }
    }
}

/// T(s) of the given profile, per channel.
pub fn transmittance_rgb_with(s_mm: f32, profile: TransmittanceProfile) -> [f32; 3] {
    let s2 = s_mm * s_mm * profile.exponent_scale();
    let mut t = [0.0f32; 3];
    for (&v, w) in SIX_GAUSSIAN_VARIANCES_MM2
        .iter()
        .zip(SIX_GAUSSIAN_WEIGHTS_RGB.iter())
    {
        let e = (-s2 / v).exp();
        for c in 0..3 {
            t[c] += w[c] * e;
        }
    }
    t
}

/// Irradiance factor at the back of the slab, eq. 5.13:
/// `max(0.3 + dot(-N, L), 0)` with the front normal's `n_dot_l = dot(N, L)`.
///
/// The 0.3 bias starts transmittance ~17 degrees before the terminator so
/// the hand-over from reflectance to transmittance has no hard edge.
pub fn back_irradiance_factor(n_dot_l: f32) -> f32 {
    (0.3 - n_dot_l).max(0.0)
}

/// Normal shrink of Listing 5.1 (`pos - 0.005 * N`) in the demo's units.
///
/// Shrinking the shaded point along its normal before the shadow-map lookup
/// keeps silhouette pixels from sampling the background depth.
pub const SHRINK_DEMO_UNITS: f32 = 0.005;

/// [`SHRINK_DEMO_UNITS`] converted to scene units: the demo's 1-unit head is
/// taken as [`DEMO_UNIT_MM`] mm, so the shrink is `0.005 * 230 = 1.15` mm,
/// expressed in a scene with `mm_per_unit` millimetres per unit.
pub fn shrink_units(mm_per_unit: f32) -> f32 {
    SHRINK_DEMO_UNITS * DEMO_UNIT_MM / mm_per_unit
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_integral_profile_is_eq_5_12_at_s_over_sqrt2() {
        for s in [0.0f32, 0.5, 1.0, 2.0, 3.0, 5.0] {
            let a = transmittance_rgb_with(s, TransmittanceProfile::Integral);
            let b = transmittance_rgb_with(s / 2f32.sqrt(), TransmittanceProfile::Thesis);
            for c in 0..3 {
                assert!((a[c] - b[c]).abs() < 1e-6, "s {s}: {a:?} vs {b:?}");
            }
        }
        // At an ear's 3 mm the integral transmits several times more red.
        let t = transmittance_rgb_with(3.0, TransmittanceProfile::Thesis)[0];
        let i = transmittance_rgb_with(3.0, TransmittanceProfile::Integral)[0];
        assert!(i > 2.0 * t, "{i} vs {t}");
        assert!(
            "integral".parse::<TransmittanceProfile>().is_ok()
                && "x".parse::<TransmittanceProfile>().is_err()
        );
    }

    #[test]
    fn zero_distance_is_sum_of_weights() {
        let t = transmittance_rgb(0.0);
        for c in 0..3 {
            let sum: f32 = SIX_GAUSSIAN_WEIGHTS_RGB.iter().map(|w| w[c]).sum();
            assert!((t[c] - sum).abs() < 1e-6);
            assert!((t[c] - 1.0).abs() < 1e-5);
        }
    }

    #[test]
    fn decays_and_red_travels_furthest() {
        let mut prev = transmittance_rgb(0.0);
        for i in 1..=40 {
            let t = transmittance_rgb(i as f32 * 0.1);
            for c in 0..3 {
                assert!(t[c] <= prev[c], "not monotone at {i}");
            }
            prev = t;
        }
        let t = transmittance_rgb(1.0);
        assert!(t[0] > t[1] && t[1] > t[2], "{t:?}");
        // Hand-evaluated reference at s = 1 mm, red channel.
        let want = 0.233 * (-1.0f32 / 0.0064).exp()
            + 0.1 * (-1.0f32 / 0.0484).exp()
            + 0.118 * (-1.0f32 / 0.187).exp()
            + 0.113 * (-1.0f32 / 0.567).exp()
            + 0.358 * (-1.0f32 / 1.99).exp()
            + 0.078 * (-1.0f32 / 7.41).exp();
        assert!((t[0] - want).abs() < 1e-6);
    }

    #[test]
    fn back_irradiance_bias() {
        assert_eq!(back_irradiance_factor(1.0), 0.0);
        assert_eq!(back_irradiance_factor(0.3), 0.0);
        assert!((back_irradiance_factor(0.0) - 0.3).abs() < 1e-7);
        assert!((back_irradiance_factor(-1.0) - 1.3).abs() < 1e-6);
    }

    #[test]
    fn shrink_scales_with_scene_units() {
        assert!((shrink_units(DEMO_UNIT_MM) - 0.005).abs() < 1e-9);
        assert!((shrink_units(1000.0) - 0.00115).abs() < 1e-9);
        assert!((shrink_units(1.0) - 1.15).abs() < 1e-6);
    }
}
