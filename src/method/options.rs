//! The options a method declares (its knobs: CLI flag, help, default) and the
//! values a run gives them. The CLI, `eval`'s settings and the tests all set
//! options by key; each method parses its own into a typed configuration.

use std::collections::BTreeMap;
use std::str::FromStr;

use anyhow::{bail, Context as _, Result};
use serde::Serialize;

/// How an option is spelled on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OptKind {
    /// `--key VALUE`.
    Value,
    /// A switch that turns a default-on feature off: `--no-key` sets "false".
    NoFlag,
    /// A value whose long flag (and clap id) is not its key, where the key
    /// would clash with a command's own flag (`profile` against budget's and
    /// plan's hardware `--profile`): `--FLAG value` sets the key.
    Flagged(&'static str),
}

/// One knob of a method.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OptSpec {
    /// The key (and, for `Value`, the long flag without its dashes).
    pub key: &'static str,
    pub kind: OptKind,
    /// The value when none is given (`NoFlag`: "true").
    pub default: &'static str,
    /// What it does, with its valid values or range.
    pub help: &'static str,
}

impl OptSpec {
    /// The long flag as typed, without the dashes.
    pub fn flag(&self) -> String {
        match self.kind {
            OptKind::Value => self.key.to_string(),
            OptKind::NoFlag => format!("no-{}", self.key),
            OptKind::Flagged(flag) => flag.to_string(),
        }
    }
}

/// Option values given explicitly (by the CLI, an eval setting, a test), by
/// key. Keys of every method may be present: `eval` passes one set to all of
/// them, and each method reads only its own.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, serde::Deserialize)]
pub struct MethodOptions(BTreeMap<String, String>);

impl MethodOptions {
    pub fn set(&mut self, key: &str, value: impl Into<String>) {
        self.0.insert(key.to_string(), value.into());
    }

    /// This set with `overrides` applied on top.
    pub fn with(&self, overrides: &[(&str, &str)]) -> Self {
        let mut o = self.clone();
        for (k, v) in overrides {
            o.set(k, *v);
        }
        o
    }

    pub fn given(&self, key: &str) -> Option<&str> {
        self.0.get(key).map(String::as_str)
    }

    pub fn keys(&self) -> impl Iterator<Item = &str> {
        self.0.keys().map(String::as_str)
    }
}

/// One method's view of the options: its specs and the given values.
#[derive(Clone, Copy)]
pub struct Opts<'a> {
    pub specs: &'static [OptSpec],
    pub given: &'a MethodOptions,
}

impl<'a> Opts<'a> {
    fn spec(&self, key: &str) -> &'static OptSpec {
        self.specs
            .iter()
            .find(|s| s.key == key)
            .unwrap_or_else(|| panic!("option '{key}' is not declared by this method"))
    }

    /// The value of `key`: given, or its default.
    pub fn raw(&self, key: &str) -> &'a str {
        let spec = self.spec(key);
        self.given.given(key).unwrap_or(spec.default)
    }

    /// The value of `key` parsed, with an error that names the flag.
    pub fn parse<T: FromStr>(&self, key: &str) -> Result<T>
    where
        T::Err: std::fmt::Display,
    {
        let spec = self.spec(key);
        let v = self.raw(key);
        v.trim()
            .parse::<T>()
            .map_err(|e| anyhow::anyhow!("{e}"))
            .with_context(|| format!("--{} '{v}'", spec.flag()))
    }

    /// A switch's value.
    pub fn flag(&self, key: &str) -> Result<bool> {
        match self.raw(key) {
            "true" => Ok(true),
            "false" => Ok(false),
            other => bail!(
                "--{}: expected true or false, got '{other}'",
                self.spec(key).flag()
            ),
        }
    }

    /// An optional three-channel value `R,G,B` (`""`: not given).
    pub fn rgb(&self, key: &str) -> Result<Option<[f32; 3]>> {
        let v = self.raw(key).trim();
        if v.is_empty() {
            return Ok(None);
        }
        let flag = self.spec(key).flag();
        let parts: Vec<f32> = v
            .split(',')
            .map(|p| p.trim().parse::<f32>())
            .collect::<Result<_, _>>()
            .with_context(|| format!("--{flag} '{v}': not a number"))?;
        match parts[..] {
            [r, g, b] => Ok(Some([r, g, b])),
            _ => bail!(
                "--{flag} takes three comma-separated values R,G,B, got {}",
                parts.len()
            ),
        }
    }

    /// Every option of the method with its value (given or default), for reports.
    pub fn resolved(&self) -> BTreeMap<&'static str, String> {
        self.specs
            .iter()
            .map(|s| (s.key, self.raw(s.key).to_string()))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SPECS: &[OptSpec] = &[
        OptSpec {
            key: "samples",
            kind: OptKind::Value,
            default: "17",
            help: "",
        },
        OptSpec {
            key: "lod",
            kind: OptKind::NoFlag,
            default: "true",
            help: "",
        },
        OptSpec {
            key: "strength",
            kind: OptKind::Value,
            default: "",
            help: "",
        },
    ];

    #[test]
    fn defaults_given_values_and_errors_that_name_the_flag() {
        let mut given = MethodOptions::default();
        let o = Opts {
            specs: SPECS,
            given: &given,
        };
        assert_eq!(o.parse::<usize>("samples").unwrap(), 17);
        assert!(o.flag("lod").unwrap());
        assert_eq!(o.rgb("strength").unwrap(), None);
        given.set("samples", "x9");
        given.set("lod", "false");
        given.set("strength", "0.1,0.2");
        let o = Opts {
            specs: SPECS,
            given: &given,
        };
        let e = format!("{:#}", o.parse::<usize>("samples").unwrap_err());
        assert!(e.contains("--samples 'x9'"), "{e}");
        assert!(!o.flag("lod").unwrap());
        let e = format!("{:#}", o.rgb("strength").unwrap_err());
        assert!(e.contains("three comma-separated"), "{e}");
        assert_eq!(SPECS[1].flag(), "no-lod");
        assert_eq!(o.resolved()["samples"], "x9");
        let more = given.with(&[("samples", "33")]);
        assert_eq!(more.given("samples"), Some("33"));
    }
}
