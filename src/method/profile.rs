//! Which diffusion profile a method approximates, and so which ground truth it
//! is scored against: d'Eon's six Gaussians (Table 4.2, the sources' skin) or
//! Burley's normalized diffusion matched to the same skin (`skin::burley`).
//! The profile itself is [`Profile`] (`skin::profile`, pure); this is the
//! option that names it.

use super::{OptKind, OptSpec};
pub use crate::skin::diffusion::Profile;

/// The option's key (`--sss-profile`: `--profile` is `budget`'s profile of a
/// GPU).
pub const KEY: &str = "sss-profile";

/// The option every method that can take either profile reads.
pub const OPTION: OptSpec = OptSpec {
    key: KEY,
    kind: OptKind::Value,
    default: "six-gaussian",
    help: "six-gaussian (d'Eon's fit, Table 4.2) | burley (Burley's normalized diffusion matched to the same skin: total reflectance and mean radius per channel)",
};
