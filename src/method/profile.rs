//! Which diffusion profile a method approximates, and so which ground truth it
//! is scored against: d'Eon's six Gaussians (Table 4.2, the sources' skin) or
//! Burley's normalized diffusion matched to the same skin (`skin::burley`,
//! [`crate::skin::kernel::burley_profile`]). The profile's math is in `skin`;
//! this is the option that names it.

use std::str::FromStr;

use anyhow::{bail, Result};

use super::{MethodEntry, MethodOptions, OptKind, OptSpec};
use crate::skin::burley::BurleyParams;
use crate::skin::kernel::{burley_profile, Preset};

/// The option every method that can take either profile reads (`profile=`
/// in settings and `METHOD:profile=...` rules; `--diffusion-profile` on the
/// command line, where budget and plan have a hardware `--profile`).
pub const OPTION: OptSpec = OptSpec {
    key: "profile",
    kind: OptKind::Flagged("diffusion-profile"),
    default: "six-gaussian",
    help: "six-gaussian (d'Eon's fit, Table 4.2) | burley (Burley's normalized diffusion matched to the same skin: total reflectance and mean radius per channel)",
};

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
            Profile::SixGaussian => crate::skin::profile::profile_rgb(r_mm),
            Profile::Burley => burley_profile().profile(r_mm),
        }
    }

    /// Burley's parameters when this is Burley's profile.
    pub fn burley(self) -> Option<BurleyParams> {
        match self {
            Profile::SixGaussian => None,
            Profile::Burley => Some(burley_profile()),
        }
    }
}

/// The one place that says which profile a method's setting approximates,
/// and so which ground truth it is scored against: a method with the
/// `profile` option ([`OPTION`]: the ground truth, and any method that takes
/// either) its value; separable's `preset=burley` (Burley's marginal) Burley;
/// everything else the six Gaussians (the sources' profile). `given` holds
/// the setting's options (every method's keys may be present).
pub fn approximated(method: &MethodEntry, given: &MethodOptions) -> Result<Profile> {
    let o = method.opts(given);
    if method.options.iter().any(|s| s.key == OPTION.key) {
        return o.parse(OPTION.key);
    }
    if std::ptr::eq(method, &super::separable::ENTRY) {
        let preset: Preset = o.parse("preset")?;
        if preset == Preset::Burley {
            return Ok(Profile::Burley);
        }
    }
    Ok(Profile::SixGaussian)
}

impl Profile {
    /// Whether this is the six Gaussians (eval.json leaves the profile out
    /// then, as it did before there were two).
    pub fn is_six_gaussian(&self) -> bool {
        *self == Profile::SixGaussian
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
    fn each_setting_names_its_profile() {
        let m = |name| crate::method::lookup(name).unwrap();
        let given = |kv: &[(&str, &str)]| MethodOptions::default().with(kv);
        let of = |name, kv: &[(&str, &str)]| approximated(m(name), &given(kv)).unwrap();
        assert_eq!(of("separable", &[]), Profile::SixGaussian);
        assert_eq!(
            of("separable", &[("preset", "physical")]),
            Profile::SixGaussian
        );
        assert_eq!(of("separable", &[("preset", "burley")]), Profile::Burley);
        assert_eq!(of("reference", &[]), Profile::SixGaussian);
        assert_eq!(of("reference", &[("profile", "burley")]), Profile::Burley);
        // A method without the option ignores another method's key.
        assert_eq!(of("ssg", &[("profile", "burley")]), Profile::SixGaussian);
        // Every method with the option reads it (gather2d and any to come).
        for e in crate::method::METHODS {
            if e.options.iter().any(|s| s.key == OPTION.key) {
                assert_eq!(
                    approximated(e, &given(&[("profile", "burley")])).unwrap(),
                    Profile::Burley
                );
            }
        }
        assert!(approximated(m("reference"), &given(&[("profile", "dipole")])).is_err());
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
