//! Several SSS methods in one frame: which method (and which settings) each
//! character gets, and how characters with the same choice form one group.
//!
//! A [`Mix`] holds one [`Choice`] per character, in the order the frame places
//! its characters (`Framing::instances`). Characters whose choices resolve to
//! the same method and option values share one [`Group`]: one method instance,
//! one stencil code, one set of passes. Where the choices come from: `--assign`
//! rules ([`assign`]) or a plan file ([`plan_file`]), both checked against the
//! method registry before any device opens.
//!
//! A character may also be **cross-fading** ([`Fade`]) from the setting it had
//! to the one it has now (a re-planned sequence's switch, docs/plan-over-time.md):
//! it then forms a group of its own, whose old setting runs beside its new one
//! and is blended into the result by the fade's weight.

pub mod assign;
pub mod plan_file;

use std::collections::BTreeMap;

use anyhow::{bail, Context as _, Result};
use serde::{Deserialize, Serialize};

use crate::method::{lookup, none, EvalSetting, MethodEntry, MethodOptions, STENCIL_SKIN};

/// Bits of the 8-bit stencil above the skin bit (`method::STENCIL_SKIN`, the
/// one place it is written) that carry the group index.
pub const GROUP_BITS: u32 = 7;
/// How many groups one frame can tell apart by stencil (2^7).
pub const MAX_GROUPS: usize = 1 << GROUP_BITS;

/// The stencil value of group `g`'s skin pixels: the skin bit and the index
/// above it. Group 0 is the skin bit alone, so a frame with one method writes
/// and tests exactly what it did before groups existed.
pub fn stencil_code(group: usize) -> u32 {
    debug_assert!(group < MAX_GROUPS);
    STENCIL_SKIN | ((group as u32) << 1)
}

/// One character's method and the option values given to it.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Choice {
    /// The registry name (aliases are resolved to it).
    pub method: String,
    /// Option values by key (only those given; the rest take their defaults).
    #[serde(default)]
    pub options: BTreeMap<String, String>,
}

impl Choice {
    /// `method` (a name or alias) with `options`, checked against the registry:
    /// an unknown method, a key the method does not declare or a value its
    /// checks refuse is an error that names them.
    pub fn new(method: &str, options: BTreeMap<String, String>) -> Result<Choice> {
        let entry = lookup(method)?;
        if entry.ground_truth {
            bail!(
                "'{}' is the ground truth: it renders a whole frame, not one character's share",
                entry.name
            );
        }
        for k in options.keys() {
            if !entry.options.iter().any(|o| o.key == k) {
                let valid: Vec<&str> = entry.options.iter().map(|o| o.key).collect();
                bail!(
                    "{} has no option '{k}' (its options: {})",
                    entry.name,
                    if valid.is_empty() {
                        "none".to_string()
                    } else {
                        valid.join(", ")
                    }
                );
            }
        }
        let c = Choice {
            method: entry.name.to_string(),
            options,
        };
        (entry.check)(&entry.opts(&c.method_options())).with_context(|| c.label())?;
        Ok(c)
    }

    /// No SSS for this character (the registry's `no_sss` entry, `method::none`).
    pub fn none() -> Choice {
        Choice {
            method: none().name.into(),
            options: BTreeMap::new(),
        }
    }

    /// The method's registry row (the name was checked when the choice was made).
    pub fn entry(&self) -> Result<&'static MethodEntry> {
        lookup(&self.method)
    }

    pub fn is_none(&self) -> bool {
        self.method == none().name
    }

    /// The options as the method reads them.
    pub fn method_options(&self) -> MethodOptions {
        let mut o = MethodOptions::default();
        for (k, v) in &self.options {
            o.set(k, v.clone());
        }
        o
    }

    /// Every option of the method with its value (given or default): two
    /// choices with equal resolved options render alike.
    pub fn resolved(&self) -> Result<BTreeMap<&'static str, String>> {
        let e = self.entry()?;
        Ok(e.opts(&self.method_options()).resolved())
    }

    /// The `eval` setting these options are (the accuracy model is measured
    /// per setting), if any: the one whose resolved options equal these.
    pub fn eval_setting(&self) -> Result<Option<&'static EvalSetting>> {
        let e = self.entry()?;
        let mine = self.resolved()?;
        Ok(e.eval.iter().find(|s| {
            let theirs = e.opts(&MethodOptions::default().with(s.options)).resolved();
            theirs == mine
        }))
    }

    /// The choice as `--assign` spells it: `method[:key=value...]`.
    pub fn label(&self) -> String {
        let mut s = self.method.clone();
        for (k, v) in &self.options {
            s.push_str(&format!(":{k}={v}"));
        }
        s
    }
}

/// A character between two settings: `from` (the setting it had) still runs on
/// it and its result counts `weight` of the character's diffuse light, the
/// new setting's the rest (`out = weight * from + (1 - weight) * new`).
#[derive(Clone, Debug, PartialEq)]
pub struct Fade {
    pub from: Choice,
    /// The old setting's share, in (0, 1).
    pub weight: f64,
}

impl Fade {
    /// A fade from `from` at `weight`, checked: a share strictly between 0 and
    /// 1 (0 is no fade, 1 the old setting alone).
    pub fn new(from: Choice, weight: f64) -> Result<Fade> {
        if !(weight.is_finite() && weight > 0.0 && weight < 1.0) {
            bail!("fade weight {weight} is not a share strictly between 0 and 1");
        }
        Ok(Fade { from, weight })
    }
}

/// One method instance of a mixed frame: its choice, its characters (frame
/// indices, ascending) and its stencil code; a fading character's group also
/// holds its fade.
#[derive(Clone, Debug, PartialEq)]
pub struct Group {
    pub index: usize,
    pub choice: Choice,
    pub characters: Vec<usize>,
    pub fade: Option<Fade>,
}

impl Group {
    /// The stencil value the geometry pass writes on this group's skin pixels
    /// and its passes test.
    pub fn stencil(&self) -> u32 {
        stencil_code(self.index)
    }
}

/// A method per character, and the characters cross-fading.
#[derive(Clone, Debug, PartialEq)]
pub struct Mix {
    pub choices: Vec<Choice>,
    /// Fading characters by frame index.
    pub fades: BTreeMap<usize, Fade>,
}

impl Mix {
    /// Every one of `n` characters with `choice`.
    pub fn uniform(choice: Choice, n: usize) -> Mix {
        Mix::new(vec![choice; n])
    }

    /// `choices` with no fade.
    pub fn new(choices: Vec<Choice>) -> Mix {
        Mix {
            choices,
            fades: BTreeMap::new(),
        }
    }

    /// Whether every character has the same method and resolved options.
    pub fn is_uniform(&self) -> Result<bool> {
        Ok(self.groups()?.len() <= 1)
    }

    /// The groups, in the order of their first character; characters whose
    /// choices resolve alike share one. Characters with no SSS form a group
    /// too (it records no passes). A fading character forms a group of its
    /// own: its old setting's passes test its stencil code, which must mark it
    /// alone. More than [`MAX_GROUPS`] groups cannot be told apart by the
    /// stencil: an error that says so.
    pub fn groups(&self) -> Result<Vec<Group>> {
        let mut groups: Vec<(BTreeMap<&'static str, String>, Group)> = Vec::new();
        for (i, c) in self.choices.iter().enumerate() {
            let key = c.resolved()?;
            let fade = self.fades.get(&i).cloned();
            if let Some(f) = &fade {
                if f.from.method == c.method && f.from.resolved()? == key {
                    bail!(
                        "character {i} fades from {} to the same setting",
                        f.from.label()
                    );
                }
            }
            match groups.iter_mut().find(|(k, g)| {
                fade.is_none() && g.fade.is_none() && g.choice.method == c.method && *k == key
            }) {
                Some((_, g)) => g.characters.push(i),
                None => {
                    let index = groups.len();
                    groups.push((
                        key,
                        Group {
                            index,
                            choice: c.clone(),
                            characters: vec![i],
                            fade,
                        },
                    ));
                }
            }
        }
        if let Some(&c) = self.fades.keys().find(|&&c| c >= self.choices.len()) {
            bail!(
                "character {c} fades but does not exist (the frame has {})",
                self.choices.len()
            );
        }
        if groups.len() > MAX_GROUPS {
            bail!(
                "{} different method settings in one frame; the stencil tells {MAX_GROUPS} apart \
                 ({GROUP_BITS} bits above the skin bit): give characters fewer distinct settings",
                groups.len()
            );
        }
        Ok(groups.into_iter().map(|(_, g)| g).collect())
    }

    /// The group of every character (by frame index).
    pub fn group_of(&self) -> Result<Vec<usize>> {
        let mut out = vec![0; self.choices.len()];
        for g in self.groups()? {
            for &c in &g.characters {
                out[c] = g.index;
            }
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn choice(m: &str, kv: &[(&str, &str)]) -> Choice {
        Choice::new(
            m,
            kv.iter()
                .map(|(k, v)| (k.to_string(), v.to_string()))
                .collect(),
        )
        .unwrap()
    }

    #[test]
    fn stencil_codes_keep_the_skin_bit_and_group_zero_is_the_old_code() {
        assert_eq!(stencil_code(0), STENCIL_SKIN);
        assert_eq!(stencil_code(1), 3);
        assert_eq!(stencil_code(MAX_GROUPS - 1), 255);
        for g in 0..MAX_GROUPS {
            assert_eq!(stencil_code(g) & STENCIL_SKIN, STENCIL_SKIN);
        }
    }

    #[test]
    fn choices_resolving_alike_share_a_group() {
        let mix = Mix::new(vec![
            choice("ssg", &[("fit", "4")]),
            choice("separable", &[]),
            choice("ssg", &[("fit", "4")]),
            choice("none", &[]),
            // The default sample count spelled out is the same setting.
            choice("separable", &[("samples", "17")]),
        ]);
        let g = mix.groups().unwrap();
        assert_eq!(g.len(), 3);
        assert_eq!(g[0].characters, vec![0, 2]);
        assert_eq!(g[1].characters, vec![1, 4]);
        assert_eq!(g[2].characters, vec![3]);
        assert_eq!(mix.group_of().unwrap(), vec![0, 1, 0, 2, 1]);
        assert!(!mix.is_uniform().unwrap());
        assert!(Mix::uniform(choice("ssg", &[]), 4).is_uniform().unwrap());
    }

    #[test]
    fn bad_choices_are_errors_that_name_what_is_wrong() {
        let e = Choice::new("ssgg", BTreeMap::new())
            .unwrap_err()
            .to_string();
        assert!(e.contains("unknown method 'ssgg'"), "{e}");
        let e = Choice::new("ssg", [("samples".into(), "9".into())].into())
            .unwrap_err()
            .to_string();
        assert!(e.contains("ssg has no option 'samples'"), "{e}");
        let e = format!(
            "{:#}",
            Choice::new("ssg", [("fit".into(), "5".into())].into()).unwrap_err()
        );
        assert!(e.contains("ssg:fit=5"), "{e}");
        let e = Choice::new("reference", BTreeMap::new())
            .unwrap_err()
            .to_string();
        assert!(e.contains("ground truth"), "{e}");
    }

    #[test]
    fn eval_settings_are_found_by_their_resolved_options() {
        let c = choice("ssg", &[("fit", "4")]);
        assert_eq!(c.eval_setting().unwrap().unwrap().label, "4 Gaussians, LOD");
        let c = choice("separable", &[("samples", "21")]);
        assert!(c.eval_setting().unwrap().is_none());
        assert_eq!(c.label(), "separable:samples=21");
    }

    #[test]
    fn too_many_groups_is_an_error() {
        let choices = (0..MAX_GROUPS + 1)
            .map(|i| choice("separable", &[("sss-width-mm", &format!("{}", i + 1))]))
            .collect();
        let e = Mix::new(choices).groups().unwrap_err().to_string();
        assert!(e.contains("tells 128 apart"), "{e}");
    }

    #[test]
    fn a_fading_character_forms_a_group_of_its_own() {
        let mut mix = Mix::new(vec![
            choice("separable", &[]),
            choice("separable", &[]),
            choice("ssg", &[]),
        ]);
        mix.fades
            .insert(1, Fade::new(choice("ssg", &[]), 0.25).unwrap());
        let g = mix.groups().unwrap();
        let chars: Vec<_> = g.iter().map(|g| g.characters.clone()).collect();
        assert_eq!(chars, vec![vec![0], vec![1], vec![2]]);
        assert_eq!(g[1].fade.as_ref().unwrap().weight, 0.25);
        assert!(g[0].fade.is_none() && g[2].fade.is_none());
        // Fading to what it had, or a share outside (0, 1), is refused.
        mix.fades.insert(
            1,
            Fade::new(choice("separable", &[("samples", "17")]), 0.5).unwrap(),
        );
        let e = mix.groups().unwrap_err().to_string();
        assert!(
            e.contains("character 1 fades from separable:samples=17 to the same setting"),
            "{e}"
        );
        for w in [0.0, 1.0, -0.5, f64::NAN] {
            assert!(Fade::new(choice("ssg", &[]), w).is_err(), "{w}");
        }
        mix.fades.clear();
        mix.fades
            .insert(3, Fade::new(choice("ssg", &[]), 0.5).unwrap());
        let e = mix.groups().unwrap_err().to_string();
        assert!(e.contains("character 3 fades but does not exist"), "{e}");
    }
}
