//! Which materials of a model are skin: scattered and written to the skin
//! stencil (every SSS pass and the ground truth's scattering read only those),
//! and which are not (eyes, teeth, hair, cloth: shaded without subsurface
//! scattering). Pure: no file, no GPU.
//!
//! # The rule, per material, the first that answers wins
//! 1. The command line: `--skin LIST` and `--not-skin LIST` (material names or
//!    indices, comma-separated). A name that matches no material, or one in
//!    both lists, is an error.
//! 2. The material's glTF `extras`: `"skin": true` or `"skin": false`.
//! 3. Its name, cut into words at every character that is not an ASCII letter
//!    or digit and where a lower-case letter meets an upper-case one
//!    (`EyeBall_L` is `eye`, `ball`, `l`), any case:
//!    - not skin: a word of [`NOT_SKIN_WORDS`] (eye, iris, teeth, hair, cloth...);
//!    - skin: otherwise a word of [`SKIN_WORDS`] (skin, face, head, body...).
//! 4. Nothing said: skin when no other material of the model is skin by 1-3
//!    (a scan's one unnamed material is its skin, as dermis always took it),
//!    else not skin (a model that names its skin says which part it is).
//!
//! One material is scattered per character (its texture-space map and its
//! ground truth are one surface): when several are skin, the one with the most
//! triangles is, and the others are drawn in their own materials without
//! scattering, with a warning naming them (`--skin` chooses).
//!
//! Every decision is one note naming the material and the step that made it.

use anyhow::{bail, Result};

/// Name words of materials that do not scatter: the eye and its parts, the
/// mouth's hard and wet parts, hair, and what a character wears.
pub const NOT_SKIN_WORDS: &[&str] = &[
    "eye",
    "eyes",
    "eyeball",
    "eyeballs",
    "cornea",
    "iris",
    "pupil",
    "sclera",
    "lens",
    "tear",
    "teeth",
    "tooth",
    "tongue",
    "gum",
    "gums",
    "hair",
    "brow",
    "brows",
    "eyebrow",
    "eyebrows",
    "lash",
    "lashes",
    "eyelash",
    "eyelashes",
    "beard",
    "moustache",
    "mustache",
    "cloth",
    "clothes",
    "clothing",
    "fabric",
    "shirt",
    "jacket",
    "coat",
    "pants",
    "trousers",
    "dress",
    "shoe",
    "shoes",
    "boot",
    "boots",
    "hat",
    "cap",
    "helmet",
    "glasses",
    "metal",
    "leather",
    "plastic",
    "glass",
    "rubber",
    "wood",
    "nail",
    "nails",
];

/// Name words of materials that scatter.
pub const SKIN_WORDS: &[&str] = &[
    "skin", "face", "head", "body", "flesh", "hand", "hands", "arm", "arms", "leg", "legs", "neck",
    "ear", "ears", "lip", "lips", "torso",
];

/// One material as the rule sees it.
#[derive(Clone, Debug, PartialEq)]
pub struct MaterialFacts {
    /// Index in the file; `None`: glTF's default material (primitives without one).
    pub index: Option<usize>,
    pub name: Option<String>,
    /// The `skin` boolean of the material's extras, when it has one.
    pub extras_skin: Option<bool>,
    pub triangles: usize,
}

impl MaterialFacts {
    /// How notes and errors name it.
    pub fn label(&self) -> String {
        match (&self.name, self.index) {
            (Some(n), Some(i)) => format!("material {i} '{n}'"),
            (None, Some(i)) => format!("material {i}"),
            (_, None) => "the default material (primitives without one)".to_string(),
        }
    }
}

/// The command line's choices (`--skin`, `--not-skin`).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SkinChoice {
    pub skin: Vec<String>,
    pub not_skin: Vec<String>,
}

impl SkinChoice {
    /// Parses the comma-separated lists; empty entries are refused.
    pub fn parse(skin: Option<&str>, not_skin: Option<&str>) -> Result<SkinChoice> {
        let list = |s: Option<&str>, flag: &str| -> Result<Vec<String>> {
            let Some(s) = s else { return Ok(Vec::new()) };
            let v: Vec<String> = s.split(',').map(|e| e.trim().to_string()).collect();
            if v.iter().any(String::is_empty) {
                bail!("{flag} '{s}': an empty material name (a list is NAME[,NAME...], names or indices)");
            }
            Ok(v)
        };
        let c = SkinChoice {
            skin: list(skin, "--skin")?,
            not_skin: list(not_skin, "--not-skin")?,
        };
        c.check()?;
        Ok(c)
    }

    /// Empty names and a name in both lists are errors.
    pub fn check(&self) -> Result<()> {
        if self
            .skin
            .iter()
            .chain(&self.not_skin)
            .any(|e| e.trim().is_empty())
        {
            bail!("--skin/--not-skin: an empty material name (a list is NAME[,NAME...], names or indices)");
        }
        if let Some(both) = self.skin.iter().find(|s| self.not_skin.contains(s)) {
            bail!("material '{both}' is given to both --skin and --not-skin");
        }
        Ok(())
    }

    pub fn is_empty(&self) -> bool {
        self.skin.is_empty() && self.not_skin.is_empty()
    }
}

/// Why a material is or is not skin (the rule's step).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Reason {
    CommandLine,
    Extras,
    Name(String),
    /// Step 4; `true`: no other material is skin.
    Unnamed {
        alone: bool,
    },
}

/// The rule's answer for one material.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Decision {
    pub skin: bool,
    pub reason: Reason,
}

impl Decision {
    /// The note that names it.
    pub fn note(&self, m: &MaterialFacts) -> String {
        let what = if self.skin {
            "skin (scattered)"
        } else {
            "not skin (drawn without scattering)"
        };
        let why = match &self.reason {
            Reason::CommandLine => "by the command line".to_string(),
            Reason::Extras => format!("by its extras (\"skin\": {})", self.skin),
            Reason::Name(w) => format!("by its name (the word '{w}')"),
            Reason::Unnamed { alone: true } => {
                "as no material is named skin (--not-skin changes it)".to_string()
            }
            Reason::Unnamed { alone: false } => {
                "as another material is skin and nothing names this one (--skin changes it)"
                    .to_string()
            }
        };
        format!("{} is {what} {why}", m.label())
    }
}

/// Words of a material name (module docs, step 3), lower case.
pub fn name_words(name: &str) -> Vec<String> {
    let mut words = Vec::new();
    let mut cur = String::new();
    let mut prev_lower = false;
    for c in name.chars() {
        if !c.is_ascii_alphanumeric() {
            if !cur.is_empty() {
                words.push(std::mem::take(&mut cur));
            }
            prev_lower = false;
            continue;
        }
        if c.is_ascii_uppercase() && prev_lower && !cur.is_empty() {
            words.push(std::mem::take(&mut cur));
        }
        prev_lower = c.is_ascii_lowercase() || c.is_ascii_digit();
        cur.push(c.to_ascii_lowercase());
    }
    if !cur.is_empty() {
        words.push(cur);
    }
    words
}

/// Step 3 alone: `Some((skin, word))` when a word of the name decides.
fn by_name(name: &str) -> Option<(bool, String)> {
    let words = name_words(name);
    if let Some(w) = words.iter().find(|w| NOT_SKIN_WORDS.contains(&w.as_str())) {
        return Some((false, w.clone()));
    }
    words
        .iter()
        .find(|w| SKIN_WORDS.contains(&w.as_str()))
        .map(|w| (true, w.clone()))
}

/// Whether `entry` (a name or an index) names `m`.
fn names(entry: &str, m: &MaterialFacts) -> bool {
    match entry.parse::<usize>() {
        Ok(i) => m.index == Some(i),
        Err(_) => m.name.as_deref() == Some(entry),
    }
}

/// The rule over every material of a model, in the order given.
pub fn decide(materials: &[MaterialFacts], choice: &SkinChoice) -> Result<Vec<Decision>> {
    choice.check()?;
    for entry in choice.skin.iter().chain(&choice.not_skin) {
        if !materials.iter().any(|m| names(entry, m)) {
            let known: Vec<String> = materials.iter().map(MaterialFacts::label).collect();
            bail!(
                "--skin/--not-skin '{entry}' names no material of the model (it has {})",
                known.join(", ")
            );
        }
    }
    let first: Vec<Option<Decision>> = materials
        .iter()
        .map(|m| {
            if choice.skin.iter().any(|e| names(e, m)) {
                return Some(Decision {
                    skin: true,
                    reason: Reason::CommandLine,
                });
            }
            if choice.not_skin.iter().any(|e| names(e, m)) {
                return Some(Decision {
                    skin: false,
                    reason: Reason::CommandLine,
                });
            }
            if let Some(skin) = m.extras_skin {
                return Some(Decision {
                    skin,
                    reason: Reason::Extras,
                });
            }
            m.name
                .as_deref()
                .and_then(by_name)
                .map(|(skin, w)| Decision {
                    skin,
                    reason: Reason::Name(w),
                })
        })
        .collect();
    let any_skin = first.iter().flatten().any(|d| d.skin);
    Ok(first
        .into_iter()
        .map(|d| {
            d.unwrap_or(Decision {
                skin: !any_skin,
                reason: Reason::Unnamed { alone: !any_skin },
            })
        })
        .collect())
}

/// The one material scattered per character: the skin material with the most
/// triangles (the first of equals); `None` when none is skin.
pub fn scattered(materials: &[MaterialFacts], decisions: &[Decision]) -> Option<usize> {
    let mut best: Option<usize> = None;
    for (i, (m, d)) in materials.iter().zip(decisions).enumerate() {
        if d.skin && best.is_none_or(|b| m.triangles > materials[b].triangles) {
            best = Some(i);
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    fn m(index: usize, name: Option<&str>, extras: Option<bool>, tris: usize) -> MaterialFacts {
        MaterialFacts {
            index: Some(index),
            name: name.map(str::to_string),
            extras_skin: extras,
            triangles: tris,
        }
    }

    #[test]
    fn names_are_cut_into_words_at_case_and_punctuation() {
        assert_eq!(name_words("EyeBall_L"), ["eye", "ball", "l"]);
        assert_eq!(name_words("lambert2SG.001"), ["lambert2", "sg", "001"]);
        assert_eq!(name_words("HEAD"), ["head"]);
        // Whole words only: "eyeliner" is not an eye, "headband" not a head.
        assert!(by_name("eyeliner").is_none() && by_name("Headband").is_none());
        assert_eq!(by_name("Teeth_upper"), Some((false, "teeth".into())));
        assert_eq!(by_name("M_Head_Skin"), Some((true, "head".into())));
        // A not-skin word wins over a skin word in the same name.
        assert_eq!(by_name("head_hair"), Some((false, "hair".into())));
    }

    #[test]
    fn each_step_answers_in_order() {
        let mats = [
            m(0, Some("Body"), None, 100),
            m(1, Some("Eyes"), None, 10),
            m(2, Some("mat_03"), None, 5),
            m(3, Some("cornea"), Some(true), 1),
        ];
        let d = decide(&mats, &SkinChoice::default()).unwrap();
        assert_eq!(
            d[0],
            Decision {
                skin: true,
                reason: Reason::Name("body".into())
            }
        );
        assert!(!d[1].skin);
        // Another material is skin, so the unnamed one is not.
        assert_eq!(
            d[2],
            Decision {
                skin: false,
                reason: Reason::Unnamed { alone: false }
            }
        );
        // Extras beat the name.
        assert_eq!(
            d[3],
            Decision {
                skin: true,
                reason: Reason::Extras
            }
        );
        // The command line beats both, by name or by index.
        let c = SkinChoice::parse(Some("2"), Some("Body,cornea")).unwrap();
        let d = decide(&mats, &c).unwrap();
        assert_eq!(
            d.iter().map(|d| d.skin).collect::<Vec<_>>(),
            [false, false, true, false]
        );
        assert!(d
            .iter()
            .all(|d| d.reason == Reason::CommandLine || d.reason == Reason::Name("eyes".into())));
        assert!(d[1]
            .note(&mats[1])
            .contains("by its name (the word 'eyes')"));
    }

    #[test]
    fn a_model_that_names_nothing_is_skin_as_scans_always_were() {
        let d = decide(&[m(0, None, None, 9)], &SkinChoice::default()).unwrap();
        assert_eq!(
            d[0],
            Decision {
                skin: true,
                reason: Reason::Unnamed { alone: true }
            }
        );
        let all_cloth = [m(0, Some("Leather"), None, 9), m(1, Some("Metal"), None, 9)];
        let d = decide(&all_cloth, &SkinChoice::default()).unwrap();
        assert!(d.iter().all(|d| !d.skin));
        assert_eq!(scattered(&all_cloth, &d), None);
    }

    #[test]
    fn one_material_is_scattered_the_largest_skin() {
        let mats = [
            m(0, Some("Face"), None, 10),
            m(1, Some("Hands"), None, 30),
            m(2, Some("Eye"), None, 50),
        ];
        let d = decide(&mats, &SkinChoice::default()).unwrap();
        assert_eq!(scattered(&mats, &d), Some(1));
    }

    #[test]
    fn bad_choices_are_one_line_errors() {
        let mats = [m(0, Some("Body"), None, 1)];
        let e = decide(&mats, &SkinChoice::parse(Some("Bod"), None).unwrap()).unwrap_err();
        assert!(
            e.to_string()
                .contains("names no material of the model (it has material 0 'Body')"),
            "{e}"
        );
        let e = SkinChoice::parse(Some("a,b"), Some("b")).unwrap_err();
        assert!(e.to_string().contains("both --skin and --not-skin"), "{e}");
        assert!(SkinChoice::parse(Some("a,,b"), None).is_err());
    }
}
