//! `--assign` rules: a method per character by index or by distance band.
//!
//! ```text
//! rules    := rule ( "," rule )*
//! rule     := selector "=" choice
//! selector := "*" | N | A "-" B | "d" A "-" [B]
//! choice   := method ( ":" key "=" value | ":" "no-" key )*
//! ```
//!
//! `N` and `A-B` are character indices (inclusive, in the frame's order: the
//! first character is 0, the one a single-character frame has); `dA-B` is a
//! band of camera distance in head heights, from A (inclusive) to B
//! (exclusive; left out: no upper end). The first rule that matches a
//! character decides it; a character no rule matches is an error (end the
//! rules with `*=METHOD`). Example: `0=ssg:fit=4,1-8=separable:preset=physical,*=none`.
//! Option values that hold commas (`strength=R,G,B`) cannot be written here:
//! use a plan file.

use std::collections::BTreeMap;

use anyhow::{bail, Context as _, Result};

use super::{Choice, Mix};

/// Which characters a rule takes.
#[derive(Clone, Debug, PartialEq)]
pub enum Selector {
    All,
    /// Indices `first..=last`.
    Indices {
        first: usize,
        last: usize,
    },
    /// Camera distance in head heights, `from <= d < to`.
    Distance {
        from: f64,
        to: f64,
    },
}

impl Selector {
    fn matches(&self, index: usize, distance_heads: f64) -> bool {
        match *self {
            Selector::All => true,
            Selector::Indices { first, last } => (first..=last).contains(&index),
            Selector::Distance { from, to } => distance_heads >= from && distance_heads < to,
        }
    }
}

/// One `selector=choice` rule.
#[derive(Clone, Debug, PartialEq)]
pub struct Rule {
    pub selector: Selector,
    pub choice: Choice,
    /// The rule as written (for errors).
    pub text: String,
}

/// The parsed `--assign` value; serialised as the rules' text (what
/// `--assign` takes), so a report's settings give the same rules back.
#[derive(Clone, Debug, PartialEq)]
pub struct Rules(pub Vec<Rule>);

impl std::fmt::Display for Rules {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let texts: Vec<&str> = self.0.iter().map(|r| r.text.as_str()).collect();
        f.write_str(&texts.join(","))
    }
}

impl serde::Serialize for Rules {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

impl<'de> serde::Deserialize<'de> for Rules {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let text = String::deserialize(d)?;
        text.parse()
            .map_err(|e: anyhow::Error| serde::de::Error::custom(format!("{e:#}")))
    }
}

fn number<T: std::str::FromStr>(s: &str, what: &str, rule: &str) -> Result<T> {
    s.trim()
        .parse::<T>()
        .map_err(|_| anyhow::anyhow!("--assign '{rule}': {what} '{s}' is not a number"))
}

fn parse_selector(s: &str, rule: &str) -> Result<Selector> {
    let s = s.trim();
    if s == "*" {
        return Ok(Selector::All);
    }
    if let Some(band) = s.strip_prefix('d') {
        let (a, b) = band.split_once('-').with_context(|| {
            format!("--assign '{rule}': a distance band is dA-B or dA- (head heights)")
        })?;
        let from: f64 = number(a, "distance", rule)?;
        let to: f64 = if b.trim().is_empty() {
            f64::INFINITY
        } else {
            number(b, "distance", rule)?
        };
        if !(from.is_finite() && from >= 0.0 && to > from) {
            bail!("--assign '{rule}': the band d{a}-{b} is empty or negative");
        }
        return Ok(Selector::Distance { from, to });
    }
    match s.split_once('-') {
        Some((a, b)) => {
            let first: usize = number(a, "character", rule)?;
            let last: usize = number(b, "character", rule)?;
            if last < first {
                bail!("--assign '{rule}': the range {first}-{last} runs backwards");
            }
            Ok(Selector::Indices { first, last })
        }
        None => {
            let i: usize = number(s, "character", rule)?;
            Ok(Selector::Indices { first: i, last: i })
        }
    }
}

/// `method[:key=value|:no-key...]` as a checked choice.
pub fn parse_choice(s: &str) -> Result<Choice> {
    let mut parts = s.split(':');
    let method = parts.next().unwrap_or("").trim();
    if method.is_empty() {
        bail!("'{s}': no method named");
    }
    let mut options = BTreeMap::new();
    for p in parts {
        let p = p.trim();
        let (k, v) = match p.split_once('=') {
            Some((k, v)) => (k.trim(), v.trim()),
            None => match p.strip_prefix("no-") {
                Some(k) => (k, "false"),
                None => bail!("'{s}': option '{p}' is not key=value or no-key"),
            },
        };
        if options.insert(k.to_string(), v.to_string()).is_some() {
            bail!("'{s}': option '{k}' given twice");
        }
    }
    Choice::new(method, options)
}

impl std::str::FromStr for Rules {
    type Err = anyhow::Error;
    fn from_str(s: &str) -> Result<Rules> {
        let mut rules = Vec::new();
        for text in s.split(',') {
            let text = text.trim();
            if text.is_empty() {
                continue;
            }
            let (sel, choice) = text.split_once('=').with_context(|| {
                format!("--assign '{text}': a rule is SELECTOR=METHOD[:k=v...]")
            })?;
            let selector = parse_selector(sel, text)?;
            let choice = parse_choice(choice).with_context(|| format!("--assign '{text}'"))?;
            rules.push(Rule {
                selector,
                choice,
                text: text.to_string(),
            });
        }
        if rules.is_empty() {
            bail!("--assign: no rule given (e.g. 0=ssg:fit=4,*=none)");
        }
        Ok(Rules(rules))
    }
}

impl Rules {
    /// The mix for characters at `distances_heads` (camera distance of each, in
    /// head heights, in the frame's order). A rule naming a character index the
    /// frame does not have, or a character no rule takes, is an error.
    pub fn resolve(&self, distances_heads: &[f64]) -> Result<Mix> {
        let n = distances_heads.len();
        for r in &self.0 {
            if let Selector::Indices { last, .. } = r.selector {
                if last >= n {
                    bail!(
                        "--assign '{}': character {last} does not exist (the frame has {n}: 0-{})",
                        r.text,
                        n.saturating_sub(1)
                    );
                }
            }
        }
        let mut choices = Vec::with_capacity(n);
        for (i, &d) in distances_heads.iter().enumerate() {
            match self.0.iter().find(|r| r.selector.matches(i, d)) {
                Some(r) => choices.push(r.choice.clone()),
                None => bail!(
                    "--assign: character {i} (at {d:.2} head heights) matches no rule; end the \
                     rules with *=METHOD"
                ),
            }
        }
        Ok(Mix::new(choices))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_issue_example_parses_and_the_first_match_wins() {
        let r: Rules = "0=ssg:fit=4,1-8=separable:preset=physical,*=none"
            .parse()
            .unwrap();
        assert_eq!(r.0.len(), 3);
        let mix = r.resolve(&[2.0; 12]).unwrap();
        assert_eq!(mix.choices[0].label(), "ssg:fit=4");
        for c in &mix.choices[1..=8] {
            assert_eq!(c.label(), "separable:preset=physical");
        }
        for c in &mix.choices[9..] {
            assert!(c.is_none());
        }
    }

    #[test]
    fn distance_bands_and_switches() {
        let r: Rules = "d0-5=ssg:no-lod,d5-15=ss-jittered,d15-=none"
            .parse()
            .unwrap();
        let mix = r.resolve(&[1.0, 4.99, 5.0, 14.0, 15.0, 400.0]).unwrap();
        let labels: Vec<String> = mix.choices.iter().map(Choice::label).collect();
        assert_eq!(
            labels,
            [
                "ssg:lod=false",
                "ssg:lod=false",
                "ss-jittered",
                "ss-jittered",
                "none",
                "none"
            ]
        );
    }

    #[test]
    fn errors_are_one_line_and_name_the_rule() {
        for (text, want) in [
            ("0=ssg,9=none,*=none", "character 9 does not exist"),
            (
                "0=ssg",
                "character 1 (at 2.00 head heights) matches no rule",
            ),
            ("0=ssgg,*=none", "unknown method 'ssgg'"),
            ("0=ssg:samples=9,*=none", "ssg has no option 'samples'"),
            ("0=ssg:fit,*=none", "not key=value or no-key"),
            ("x=ssg", "character 'x' is not a number"),
            ("5-2=ssg", "runs backwards"),
            ("d5-2=ssg", "empty or negative"),
            ("ssg", "a rule is SELECTOR=METHOD"),
            ("", "no rule given"),
            ("0=ssg:fit=4:fit=6,*=none", "given twice"),
        ] {
            let e = text
                .parse::<Rules>()
                .and_then(|r| r.resolve(&[2.0, 2.0]))
                .map(|_| ())
                .unwrap_err();
            let e = format!("{e:#}");
            assert!(e.contains(want), "{text}: {e}");
            assert!(!e.contains('\n'), "{text}: {e}");
        }
    }
}
