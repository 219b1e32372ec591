//! Which diffusion profile a method approximates and its ground truth
//! integrates: d'Eon's six Gaussians (`profile`, Table 4.2) or Burley's
//! normalized diffusion matched to the same skin (`burley`,
//! [`crate::skin::kernel::burley_profile`]).

use std::str::FromStr;

use anyhow::{bail, Result};

use super::burley::BurleyParams;
use super::kernel::burley_profile;
use super::profile::profile_rgb;

/// Which diffusion profile a method approximates and its ground truth
/// integrates: d'Eon's six Gaussians (above) or Burley's normalized diffusion
/// matched to the same skin ([`crate::skin::kernel::burley_profile`]). Named
/// by `profile=` (`method::profile::OPTION`).
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "kebab-case")]
pub enum Profile {
    #[default]
    SixGaussian,
    Burley,
}

impl Profile {
    pub const ALL: [Profile; 2] = [Profile::SixGaussian, Profile::Burley];

    pub fn name(self) -> &'static str {
        match self {
            Profile::SixGaussian => "six-gaussian",
            Profile::Burley => "burley",
        }
    }

    /// The profile `R_c(r)` of every channel (r in mm, per mm^2; each
    /// integrates to 1 over the plane).
    pub fn radial_rgb(self, r_mm: f64) -> [f64; 3] {
        match self {
            Profile::SixGaussian => profile_rgb(r_mm),
            Profile::Burley => burley_profile().profile(r_mm),
        }
    }

    /// Whether this is the six Gaussians (eval.json leaves the profile out
    /// then, as it did before there were two).
    pub fn is_six_gaussian(&self) -> bool {
        *self == Profile::SixGaussian
    }

    /// Burley's parameters when this is Burley's profile.
    pub fn burley(self) -> Option<BurleyParams> {
        match self {
            Profile::SixGaussian => None,
            Profile::Burley => Some(burley_profile()),
        }
    }
}

impl FromStr for Profile {
    type Err = anyhow::Error;

    fn from_str(s: &str) -> Result<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "six-gaussian" | "six-gaussians" | "gaussians" => Ok(Profile::SixGaussian),
            "burley" => Ok(Profile::Burley),
            _ => bail!("unknown profile {s:?}; valid profiles: six-gaussian, burley"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_read_back() {
        for p in Profile::ALL {
            assert_eq!(p.name().parse::<Profile>().unwrap(), p);
        }
        assert!("dipole".parse::<Profile>().is_err());
    }

    #[test]
    fn both_profiles_integrate_to_one_over_the_plane() {
        // Midpoint rule in r on the ring area 2 pi r dr, out to 60 mm; the
        // 1/r of Burley's profile is cancelled by the ring's r.
        for p in Profile::ALL {
            let dr = 1e-4;
            let mut sum = [0.0; 3];
            let mut r = dr / 2.0;
            while r < 60.0 {
                let v = p.radial_rgb(r);
                for c in 0..3 {
                    sum[c] += v[c] * 2.0 * std::f64::consts::PI * r * dr;
                }
                r += dr;
            }
            for (c, s) in sum.iter().enumerate() {
                assert!((s - 1.0).abs() < 2e-3, "{} channel {c}: {s}", p.name());
            }
        }
    }
}
