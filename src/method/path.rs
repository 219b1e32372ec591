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
}
