//! Where a frame's scene comes from, as a value: the built-in scene or glTF
//! file `--scene` names, the texture files that replace the scene's own, and
//! the scale. Serialised into every report beside the render settings, so a
//! report names everything its frame was made from (`render --settings`).

use std::path::{Path, PathBuf};

use anyhow::Result;
use serde::{Deserialize, Serialize};

use super::gltf_load::TextureOverrides;
use super::{builtin_scene, load_gltf_scene, Scene};

/// `--scene builtin:NAME` names a built-in scene instead of a file.
pub const BUILTIN_PREFIX: &str = "builtin:";

/// The built-in scene a frame gets when no `--scene` is given.
pub const DEFAULT_BUILTIN: &str = "face";

#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SceneSource {
    /// A glTF/GLB file, or `builtin:NAME`; `None`: the embedded procedural face.
    pub scene: Option<PathBuf>,
    pub albedo: Option<PathBuf>,
    pub normal_map: Option<PathBuf>,
    pub spec_map: Option<PathBuf>,
    /// The roughness and SSS-strength maps (`--roughness-map`, `--sss-map`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub roughness_map: Option<PathBuf>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sss_map: Option<PathBuf>,
    /// The wrinkle map and its two zone masks (`--wrinkle-map`,
    /// `--wrinkle-mask1`, `--wrinkle-mask2`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wrinkle_map: Option<PathBuf>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wrinkle_mask1: Option<PathBuf>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wrinkle_mask2: Option<PathBuf>,
    /// Texture files beside the scene (or given above) are top-down.
    pub sidecar_top_down: bool,
    /// Millimetres per scene unit (`None`: from a 230 mm chin-to-crown head).
    pub mm_per_unit: Option<f32>,
    /// Materials the command line makes skin or not skin (names or indices;
    /// `crate::scene::skin_rule`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub skin: Vec<String>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub not_skin: Vec<String>,
    /// Morph weights the command line sets (`NAME=W`; the face's
    /// expressions, a file's targets).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub morph_weights: Vec<String>,
    /// The time (seconds) the scene's animation is posed at (`--time`): a
    /// file's clip (`clip`, or its first), the face's expressions, or for a
    /// scene without animation dermis's rigid turn and nod.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time: Option<f32>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub clip: Option<String>,
    /// The time each frame advances the animation (`--time-step`; from
    /// `time`, or 0): frame k of a run is posed at time + k * step.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_step: Option<f32>,
    /// The seed of a crowd's phases (`crowd_motion`; default its
    /// `DEFAULT_SEED`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub crowd_seed: Option<u64>,
    /// The skin's albedo from the two-layer skin model at a tone of the
    /// melanin axis (`--skin-tone`; `skin::colour::lut::tone_albedo`), for a
    /// skin without an albedo texture. Applied by the command wing's
    /// `load_scene` (the model lives above the scene).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub skin_tone: Option<SkinTone>,
    /// The skin drawn without its wrinkle maps (`--no-wrinkles`): the
    /// expressions move the face and crease nothing.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub no_wrinkles: bool,
}

/// Three skin tones along the melanin axis (thesis ch. 7's model:
/// `skin::colour::lut` gives each its melanin and albedo).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum SkinTone {
    Light,
    Medium,
    Dark,
}

impl SkinTone {
    pub const ALL: [SkinTone; 3] = [SkinTone::Light, SkinTone::Medium, SkinTone::Dark];
}

impl SceneSource {
    /// The built-in scene `name` (`builtin:NAME`).
    pub fn builtin_named(name: &str) -> Self {
        SceneSource {
            scene: Some(format!("{BUILTIN_PREFIX}{name}").into()),
            ..Default::default()
        }
    }

    /// The built-in scene's name (`face` when no scene is given); `None` for a file.
    pub fn builtin(&self) -> Option<&str> {
        match &self.scene {
            None => Some(DEFAULT_BUILTIN),
            Some(p) => p.to_str().and_then(|s| s.strip_prefix(BUILTIN_PREFIX)),
        }
    }

    /// The glTF file it names (`None` for a built-in scene).
    pub fn gltf(&self) -> Option<&Path> {
        match self.builtin() {
            Some(_) => None,
            None => self.scene.as_deref(),
        }
    }

    fn overrides(&self) -> TextureOverrides {
        TextureOverrides {
            albedo: self.albedo.clone(),
            normal_map: self.normal_map.clone(),
            specular_map: self.spec_map.clone(),
            roughness_map: self.roughness_map.clone(),
            sss_map: self.sss_map.clone(),
            wrinkle_map: self.wrinkle_map.clone(),
            wrinkle_masks: [self.wrinkle_mask1.clone(), self.wrinkle_mask2.clone()],
            sidecar_top_down: self.sidecar_top_down,
            skin: crate::scene::skin_rule::SkinChoice {
                skin: self.skin.clone(),
                not_skin: self.not_skin.clone(),
            },
            time: self.time,
            clip: self.clip.clone(),
        }
    }

    /// Loads the scene (every file through the bounded reader; texture
    /// files given for a built-in scene are an error, not silently unused).
    pub fn load(&self) -> Result<Scene> {
        let weights = super::parse_morph_weights(&self.morph_weights)?;
        if let Some(t) = self.time {
            crate::ranges::TIME.check(t)?;
        }
        if let Some(dt) = self.time_step {
            crate::ranges::TIME_STEP.check(dt)?;
            if !self.morph_weights.is_empty() {
                anyhow::bail!("--morph-weights poses one frame: it cannot be given with --time-step (the clip gives every frame's weights)");
            }
            if self.time.is_none() {
                // Stepping starts at 0 unless --time says.
                return SceneSource {
                    time: Some(0.0),
                    ..self.clone()
                }
                .load();
            }
        }
        if self.clip.is_some() && self.gltf().is_none() {
            anyhow::bail!("--animation names an animation of a glTF --scene; the built-in scenes have one clip each");
        }
        let mut scene = match (self.gltf(), self.builtin()) {
            (Some(path), _) => load_gltf_scene(path, &self.overrides(), self.mm_per_unit)?,
            (None, name) => builtin_scene(
                name.unwrap_or(DEFAULT_BUILTIN),
                &self.overrides(),
                self.mm_per_unit,
            )?,
        };
        // A file's clip is posed as it loads (`TextureOverrides::time`).
        if let (Some(t), None) = (self.time, self.gltf()) {
            scene.play_builtin(t);
        }
        if let Some(tracks) = &mut scene.tracks {
            tracks.seed = self.crowd_seed.unwrap_or(super::crowd_motion::DEFAULT_SEED);
            tracks.step = self.time_step;
        }
        scene.set_morph_weights(&weights)?;
        if self.no_wrinkles {
            scene.head.material.wrinkles = None;
        }
        if let Some(src) = &mut scene.source {
            src.no_wrinkles = self.no_wrinkles;
            src.skin_tone = self.skin_tone;
            src.morph_weights = self.morph_weights.clone();
            src.time = self.time;
            src.clip = self.clip.clone();
            src.crowd_seed = self.crowd_seed;
            src.time_step = self.time_step;
        }
        Ok(scene)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_source_names_a_builtin_or_a_file() {
        let none = SceneSource::default();
        assert_eq!((none.builtin(), none.gltf()), (Some("face"), None));
        let egg = SceneSource {
            scene: Some("builtin:egg".into()),
            ..Default::default()
        };
        assert_eq!((egg.builtin(), egg.gltf()), (Some("egg"), None));
        let file = SceneSource {
            scene: Some("head.glb".into()),
            ..Default::default()
        };
        assert_eq!(file.builtin(), None);
        assert_eq!(file.gltf(), Some(Path::new("head.glb")));
        // A texture given to a built-in scene is refused, not dropped.
        let bad = SceneSource {
            albedo: Some("a.png".into()),
            ..Default::default()
        };
        let e = format!("{:#}", bad.load().unwrap_err());
        assert!(e.contains("glTF --scene"), "{e}");
        let back: SceneSource =
            serde_json::from_str(&serde_json::to_string(&file).unwrap()).unwrap();
        assert_eq!(back, file);
    }
}
