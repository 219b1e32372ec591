//! `plan.json`: what `dermis plan` chose for each character of a scene, with
//! its predictions, and what `render --plan` reads back (through the files
//! door, checked against the registry and the frame before any device opens).

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{bail, Context as _, Result};
use serde::{Deserialize, Serialize};

use super::{Choice, Fade, Mix};
use crate::files::{read_text, MAX_TEXT_FILE};
use crate::scene::crowd_geometry::CharacterGeometry;

/// The plan file format's version (bumped on an incompatible change).
pub const PLAN_VERSION: u32 = 1;

/// A predicted error against the ground truth, as a fraction of the error of
/// no SSS (the eval's bands).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PredictedError {
    pub interior: f64,
    pub silhouette: f64,
}

/// One character's entry.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlannedCharacter {
    /// Frame index (the order of `Framing::instances`; 0 is the front character).
    pub character: usize,
    pub method: String,
    #[serde(default)]
    pub options: BTreeMap<String, String>,
    /// The eval setting the options are, when they are one (the accuracy model's key).
    #[serde(default)]
    pub setting: Option<String>,
    /// What the planner saw and predicted (absent in a hand-written plan).
    #[serde(default)]
    pub px_per_mm: Option<f64>,
    #[serde(default)]
    pub skin_pixels: Option<u64>,
    #[serde(default)]
    pub predicted_ms: Option<f64>,
    #[serde(default)]
    pub predicted_error: Option<PredictedError>,
    /// Its level of detail and whether it casts into the shadow map (absent
    /// in a hand-written plan or one from before: the frame chooses).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub geometry: Option<PlannedGeometry>,
    /// A cross-fade from the setting the character had (a re-planned
    /// sequence's switch, `dermis plan-motion --fade-frames`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fade: Option<PlannedFade>,
}

/// What a character draws (`scene::crowd_geometry`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlannedGeometry {
    /// 0: the full meshes; `i`: the head's `i`-th simplified level, and
    /// each other mesh its coarsest that strays no more than that one.
    pub level: u8,
    pub casts_shadow: bool,
    /// Triangles the character submits to the geometry pass at its level
    /// (what the planner counted; absent in a hand-written plan).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub triangles: Option<u64>,
}

/// The setting a character fades from and its share of the result.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlannedFade {
    pub method: String,
    #[serde(default)]
    pub options: BTreeMap<String, String>,
    /// The old setting's share of the character's diffuse light, in (0, 1).
    pub weight: f64,
}

impl PlannedFade {
    fn fade(&self) -> Result<Fade> {
        Fade::new(
            Choice::new(&self.method, self.options.clone())?,
            self.weight,
        )
    }
}

/// A whole plan.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlanFile {
    pub version: u32,
    /// The profile and skin budget planned for (absent in a hand-written plan).
    #[serde(default)]
    pub profile: Option<String>,
    #[serde(default)]
    pub budget_ms: Option<f64>,
    /// The number of characters of the scene planned for.
    pub characters: usize,
    pub assignments: Vec<PlannedCharacter>,
    /// Predicted skin-SSS time on the profile and skin-area-weighted error.
    #[serde(default)]
    pub predicted_ms: Option<f64>,
    #[serde(default)]
    pub predicted_error: Option<PredictedError>,
    /// Anything the planner wants to say about its choice (the algorithm, its bound).
    #[serde(default)]
    pub notes: Vec<String>,
    /// The run that wrote it (absent in a hand-written plan): under `run`,
    /// not flattened, as a plan file takes no field it does not know.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub run: Option<crate::header::RunHeader>,
}

impl PlanFile {
    /// Reads and checks `path` (a plan for any frame: [`PlanFile::mix`] checks
    /// it against one).
    pub fn load(path: &Path) -> Result<PlanFile> {
        let text = read_text(path, "plan file", MAX_TEXT_FILE)?;
        let plan: PlanFile = serde_json::from_str(&text)
            .map_err(|e| anyhow::anyhow!("{e}"))
            .with_context(|| format!("plan file {}: not a plan", path.display()))?;
        plan.check()
            .with_context(|| format!("plan file {}", path.display()))?;
        Ok(plan)
    }

    /// The checks that need no frame: version, each character once, every
    /// method and option known to the registry.
    pub fn check(&self) -> Result<()> {
        if self.version != PLAN_VERSION {
            bail!(
                "version {} (this dermis reads version {PLAN_VERSION})",
                self.version
            );
        }
        // The count sizes what is allocated below: held to --heads' range.
        crate::ranges::HEADS.check_as("characters", self.characters)?;
        let mut seen = vec![false; self.characters];
        for a in &self.assignments {
            if a.character >= self.characters {
                bail!(
                    "character {} does not exist (the plan is for {} characters: 0-{})",
                    a.character,
                    self.characters,
                    self.characters.saturating_sub(1)
                );
            }
            if std::mem::replace(&mut seen[a.character], true) {
                bail!("character {} is assigned twice", a.character);
            }
            Choice::new(&a.method, a.options.clone())
                .with_context(|| format!("character {}", a.character))?;
            if let Some(f) = &a.fade {
                f.fade()
                    .with_context(|| format!("character {}'s fade", a.character))?;
            }
            // What the planner saw and predicted: no number of a plan is
            // NaN, infinite or negative, read or not.
            let predicted = a.predicted_error.map(|e| [e.interior, e.silhouette]);
            for (what, v) in [("px_per_mm", a.px_per_mm), ("predicted_ms", a.predicted_ms)]
                .into_iter()
                .chain(
                    predicted
                        .into_iter()
                        .flatten()
                        .map(|v| ("predicted_error", Some(v))),
                )
            {
                if let Some(v) = v.filter(|v| !(v.is_finite() && *v >= 0.0)) {
                    bail!(
                        "character {}: {what} {v} is not a finite number >= 0",
                        a.character
                    );
                }
            }
        }
        if let Some(missing) = seen.iter().position(|s| !s) {
            bail!("character {missing} has no assignment");
        }
        // Geometry for every character or for none (the frame cannot mix its
        // own choice with a plan's).
        let with = self
            .assignments
            .iter()
            .filter(|a| a.geometry.is_some())
            .count();
        if with != 0 && with != self.assignments.len() {
            let a = self.assignments.iter().find(|a| a.geometry.is_none());
            bail!(
                "character {} has no geometry while {with} others have (give every character one, or none)",
                a.map_or(0, |a| a.character)
            );
        }
        if let Some(a) = self.assignments.iter().find(|a| {
            a.geometry
                .is_some_and(|g| g.level as usize > crate::scene::lod::LEVEL_RATIOS.len())
        }) {
            bail!(
                "character {}: level {} does not exist (levels are 0, the full meshes, to {})",
                a.character,
                a.geometry.map_or(0, |g| g.level),
                crate::scene::lod::LEVEL_RATIOS.len()
            );
        }
        // What only the groups tell: a fade to the setting it had, too many settings.
        self.mix(self.characters)?.groups()?;
        if let Some(b) = self.budget_ms {
            if !(b.is_finite() && b > 0.0) {
                bail!("budget_ms {b} is not a positive time");
            }
        }
        let predicted = self.predicted_error.map(|e| [e.interior, e.silhouette]);
        if let Some(v) = self
            .predicted_ms
            .into_iter()
            .chain(predicted.into_iter().flatten())
            .find(|v| !(v.is_finite() && *v >= 0.0))
        {
            bail!("a predicted figure {v} is not a finite number >= 0");
        }
        Ok(())
    }

    /// Every character's geometry in frame order, when the plan gives it.
    pub fn geometry(&self) -> Option<Vec<CharacterGeometry>> {
        let mut out = vec![None; self.characters];
        for a in &self.assignments {
            out[a.character] = a.geometry.map(|g| CharacterGeometry {
                level: g.level,
                casts_shadow: g.casts_shadow,
            });
        }
        out.into_iter().collect()
    }

    /// The mix for a frame of `characters` characters: an error unless the
    /// plan was made for that many.
    pub fn mix(&self, characters: usize) -> Result<Mix> {
        if characters != self.characters {
            bail!(
                "the plan is for {} characters, the scene has {characters} (give --heads {})",
                self.characters,
                self.characters
            );
        }
        let mut mix = Mix::new(vec![Choice::none(); characters]);
        for a in &self.assignments {
            mix.choices[a.character] = Choice::new(&a.method, a.options.clone())?;
            if let Some(f) = &a.fade {
                mix.fades.insert(a.character, f.fade()?);
            }
        }
        Ok(mix)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plan(json: &str) -> Result<PlanFile> {
        let p: PlanFile = serde_json::from_str(json).map_err(|e| anyhow::anyhow!("{e}"))?;
        p.check()?;
        Ok(p)
    }

    const GOOD: &str = r#"{"version":1,"characters":2,"assignments":[
        {"character":1,"method":"none"},
        {"character":0,"method":"ssg","options":{"fit":"4"},"setting":"4 Gaussians, LOD"}]}"#;

    #[test]
    fn a_plan_round_trips_into_a_mix() {
        let p = plan(GOOD).unwrap();
        let mix = p.mix(2).unwrap();
        assert_eq!(mix.choices[0].label(), "ssg:fit=4");
        assert!(mix.choices[1].is_none());
        let again: PlanFile = serde_json::from_str(&serde_json::to_string(&p).unwrap()).unwrap();
        assert_eq!(again, p);
        let e = p.mix(3).unwrap_err().to_string();
        assert!(
            e.contains("the plan is for 2 characters, the scene has 3"),
            "{e}"
        );
    }

    #[test]
    fn geometry_is_for_every_character_or_none() {
        let g0 = r#""geometry":{"level":2,"casts_shadow":false},"#;
        let g1 = r#""geometry":{"level":0,"casts_shadow":true,"triangles":9},"#;
        let both = GOOD
            .replace(r#"{"character":1,"#, &format!(r#"{{"character":1,{g1}"#))
            .replace(r#"{"character":0,"#, &format!(r#"{{"character":0,{g0}"#));
        let p = plan(&both).unwrap();
        let g = p.geometry().unwrap();
        assert_eq!((g[0].level, g[0].casts_shadow), (2, false));
        assert_eq!((g[1].level, g[1].casts_shadow), (0, true));
        assert!(plan(GOOD).unwrap().geometry().is_none());
        let one = GOOD.replace(r#"{"character":0,"#, &format!(r#"{{"character":0,{g0}"#));
        let e = format!("{:#}", plan(&one).unwrap_err());
        assert!(e.contains("character 1 has no geometry"), "{e}");
        let deep = both.replace(r#""level":2"#, r#""level":9"#);
        let e = format!("{:#}", plan(&deep).unwrap_err());
        assert!(e.contains("level 9 does not exist"), "{e}");
    }

    /// Character 1 fading from ssg to none, a quarter of ssg left.
    const FADE: &str = r#""method":"none","fade":{"method":"ssg","weight":0.25}}"#;

    #[test]
    fn a_fade_round_trips_into_the_mix() {
        let p = plan(&GOOD.replace("\"method\":\"none\"}", FADE)).unwrap();
        let mix = p.mix(2).unwrap();
        let f = &mix.fades[&1];
        assert_eq!((f.from.label().as_str(), f.weight), ("ssg", 0.25));
        assert!(!mix.fades.contains_key(&0));
        let again: PlanFile = serde_json::from_str(&serde_json::to_string(&p).unwrap()).unwrap();
        assert_eq!(again, p);
        // A plan without fades writes no fade field (older readers take it).
        assert!(!serde_json::to_string(&plan(GOOD).unwrap())
            .unwrap()
            .contains("fade"));
    }

    #[test]
    fn malformed_plans_are_one_line_errors() {
        for (json, want) in [
            (GOOD.replace("\"version\":1", "\"version\":2"), "version 2"),
            (GOOD.replace("\"ssg\"", "\"ssgg\""), "unknown method 'ssgg'"),
            (
                GOOD.replace("\"fit\"", "\"samples\""),
                "ssg has no option 'samples'",
            ),
            (
                GOOD.replace("\"character\":1", "\"character\":5"),
                "character 5 does not exist",
            ),
            (
                GOOD.replace("\"character\":1", "\"character\":0"),
                "assigned twice",
            ),
            // Issue 27: every number a plan brings is held to a range.
            (
                GOOD.replace("\"characters\":2", "\"characters\":1000000000000"),
                "characters must be within 1..=1024 (as --heads)",
            ),
            (
                GOOD.replace(
                    "\"method\":\"none\"",
                    "\"method\":\"none\",\"predicted_ms\":-1",
                ),
                "character 1: predicted_ms -1 is not a finite number >= 0",
            ),
            (
                GOOD.replace("\"characters\":2", "\"characters\":3"),
                "character 2 has no assignment",
            ),
            (
                GOOD.replace("\"method\":\"none\"", "\"methd\":\"none\""),
                "unknown field",
            ),
            ("{\"version\":1".to_string(), "EOF"),
            (
                GOOD.replace("\"method\":\"none\"}", FADE)
                    .replace("0.25", "1.5"),
                "character 1's fade: fade weight 1.5 is not a share",
            ),
            (
                GOOD.replace("\"method\":\"none\"}", FADE)
                    .replace("\"ssg\",\"weight", "\"ssgg\",\"weight"),
                "character 1's fade: unknown method 'ssgg'",
            ),
            (
                GOOD.replace(
                    "\"method\":\"none\"}",
                    &FADE.replace("\"ssg\",\"weight", "\"none\",\"weight"),
                ),
                "character 1 fades from none to the same setting",
            ),
        ] {
            let e = format!("{:#}", plan(&json).unwrap_err());
            assert!(e.contains(want), "{json}: {e}");
            assert!(!e.contains('\n'), "{e}");
        }
    }
}
