//! Which GPU path a screen-space method's blurs take: the fragment path
//! (full-screen triangles tested against the skin stencil, the sources'
//! way) or the compute path (`tiles`: one workgroup per listed skin tile,
//! shared memory, indirect dispatches).

use std::str::FromStr;

use anyhow::{bail, Result};

use super::{OptKind, OptSpec};

/// The option every method with a compute path takes (`--path`).
pub const OPTION: OptSpec = OptSpec {
    key: "path",
    kind: OptKind::Value,
    default: "fragment",
    help: "fragment (stencil-tested full-screen passes) | compute (dispatches over skin tiles)",
};

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Path {
    #[default]
    Fragment,
    Compute,
}

impl Path {
    pub fn name(self) -> &'static str {
        match self {
            Path::Fragment => "fragment",
            Path::Compute => "compute",
        }
    }
}

/// The planner's label of an eval setting on `path`: the eval label on the
/// fragment path (the sources' way, what the eval measured), the label and
/// the path's name on another ("17 samples, compute"), so both twins of a
/// setting are told apart in plans, tables and stored frames.
pub fn planned_label(eval_label: &str, path: Path) -> String {
    match path {
        Path::Fragment => eval_label.to_string(),
        other => format!("{eval_label}, {}", other.name()),
    }
}

impl FromStr for Path {
    type Err = anyhow::Error;

    fn from_str(s: &str) -> Result<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "fragment" => Ok(Path::Fragment),
            "compute" => Ok(Path::Compute),
            _ => bail!("unknown path {s:?}; valid paths: fragment, compute"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_read_back() {
        for p in [Path::Fragment, Path::Compute] {
            assert_eq!(p.name().parse::<Path>().unwrap(), p);
        }
        assert!("vertex".parse::<Path>().is_err());
    }

    #[test]
    fn a_twin_s_label_names_its_path() {
        assert_eq!(planned_label("13 taps", Path::Fragment), "13 taps");
        assert_eq!(planned_label("13 taps", Path::Compute), "13 taps, compute");
    }
}
