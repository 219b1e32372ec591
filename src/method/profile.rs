//! Which diffusion profile a method approximates, and so which ground truth it
//! is scored against: d'Eon's six Gaussians (Table 4.2, the sources' skin) or
//! Burley's normalized diffusion matched to the same skin (`skin::burley`).
//! The profile itself is [`Profile`] (`skin::diffusion`, pure); this is the
//! option that names it.

use anyhow::Result;

use super::{MethodEntry, MethodOptions, OptKind, OptSpec};
pub use crate::skin::diffusion::Profile;
use crate::skin::kernel::Preset;

/// The option's key (`profile=` in settings and rules).
pub const KEY: &str = "profile";

/// The option every method that can take either profile reads (`profile=`
/// in settings and `METHOD:profile=...` rules; `--diffusion-profile` on the
/// command line, where budget and plan have a hardware `--profile`).
pub const OPTION: OptSpec = OptSpec {
    key: KEY,
    kind: OptKind::Flagged("diffusion-profile"),
    default: "six-gaussian",
    help: "six-gaussian (d'Eon's fit, Table 4.2) | burley (Burley's normalized diffusion matched to the same skin: total reflectance and mean radius per channel)",
};

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

#[cfg(test)]
mod tests {
    use super::*;

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
}
