//! From the command line to a checked frame, once (issue 27): the frame
//! options (or a `--settings` file) become a scene source and render
//! settings, the scene is loaded, and a [`FrameRequest`] validates the
//! settings and resolves the character groups. Every check is made here,
//! before any device opens; nothing below checks again.

use std::collections::BTreeSet;
use std::path::Path;

use anyhow::{bail, Context as _, Result};
use clap::parser::ValueSource;
use clap::ArgMatches;

use super::cli::{flag, FrameArgs, View};
use crate::method::lookup;
use crate::mix::plan_file::PlanFile;
use crate::render::request::FrameSettings;
use crate::render::settings::{Assignment, ShotPreset};
use crate::render::RenderSettings;
use crate::scene::source::SceneSource;
use crate::scene::Scene;
use crate::vk::context::{Context, ContextDesc};

/// The options given on the command line (clap ids), as opposed to defaults.
#[derive(Clone, Debug, Default)]
pub struct Given(BTreeSet<String>);

impl Given {
    /// The options of the subcommand `m` that the command line gave.
    pub fn of(m: &ArgMatches) -> Given {
        Given(
            m.ids()
                .map(|id| id.as_str())
                .filter(|id| m.value_source(id) == Some(ValueSource::CommandLine))
                .map(str::to_string)
                .collect(),
        )
    }

    /// Whether the option with clap id `id` was given.
    pub fn has(&self, id: &str) -> bool {
        self.0.contains(id)
    }

    pub fn ids(&self) -> impl Iterator<Item = &str> {
        self.0.iter().map(String::as_str)
    }

    /// These ids (tests).
    pub fn from_ids(ids: &[&str]) -> Given {
        Given(ids.iter().map(|s| s.to_string()).collect())
    }
}

/// The frame options that are not frame settings: a `--settings` file does
/// not give them, so they may come with one.
const NOT_SETTINGS: [&str; 3] = ["device", "validate", "settings"];

/// Where the frame comes from and what it is asked to be, from the frame
/// options or their `--settings` file; nothing checked yet but the file.
pub fn frame_settings(a: &FrameArgs, given: &Given) -> Result<(SceneSource, RenderSettings)> {
    match &a.settings {
        Some(path) => {
            // Every other frame option would be a second, silent source.
            let frame_ids: BTreeSet<String> =
                <FrameArgs as clap::Args>::augment_args(clap::Command::new("frame"))
                    .get_arguments()
                    .map(|a| a.get_id().to_string())
                    .collect();
            if let Some(id) = given
                .ids()
                .find(|id| frame_ids.contains(*id) && !NOT_SETTINGS.contains(id))
            {
                bail!(
                    "{} cannot be given with --settings: the file gives every frame setting",
                    flag(id)
                );
            }
            let fs = read_settings(path)?;
            let scene = fs.scene.with_context(|| {
                format!(
                    "--settings {}: its scene was built in code, not read from a file or built in: no command can load it",
                    path.display()
                )
            })?;
            Ok((scene, fs.render))
        }
        None => Ok((scene_source(a), settings(a)?)),
    }
}

/// Reads the frame settings of a `report.json` (its `settings`) or of a
/// settings file of that shape.
pub fn read_settings(path: &Path) -> Result<FrameSettings> {
    let text = crate::files::read_text(path, "settings file", crate::files::MAX_TEXT_FILE)?;
    let v: serde_json::Value = serde_json::from_str(&text)
        .map_err(|e| anyhow::anyhow!("{e}"))
        .with_context(|| format!("--settings {}: not JSON", path.display()))?;
    // A report holds its settings under `settings`, next to its run header.
    let (v, what) = match v.get("passes") {
        Some(_) => (
            v.get("settings").cloned().with_context(|| {
                format!(
                    "--settings {}: a report from before reports held their settings (dermis 0.1 before issue 27)",
                    path.display()
                )
            })?,
            "report settings",
        ),
        None => (v, "settings"),
    };
    serde_json::from_value(v)
        .map_err(|e| anyhow::anyhow!("{e}"))
        .with_context(|| format!("--settings {}: not {what}", path.display()))
}

/// The scene source the options name.
pub fn scene_source(a: &FrameArgs) -> SceneSource {
    SceneSource {
        scene: a.scene.clone(),
        albedo: a.albedo.clone(),
        normal_map: a.normal_map.clone(),
        spec_map: a.spec_map.clone(),
        roughness_map: a.roughness_map.clone(),
        sss_map: a.sss_map.clone(),
        wrinkle_map: a.wrinkle_map.clone(),
        wrinkle_mask1: a.wrinkle_mask1.clone(),
        wrinkle_mask2: a.wrinkle_mask2.clone(),
        sidecar_top_down: a.sidecar_top_down,
        mm_per_unit: a.mm_per_unit,
        skin: a.skin.clone(),
        not_skin: a.not_skin.clone(),
        morph_weights: a.morph_weights.clone(),
        time: a.time,
        clip: a.animation.clone(),
        crowd_seed: a.crowd_seed,
        time_step: a.time_step,
        skin_tone: a.skin_tone,
        no_wrinkles: a.no_wrinkles,
    }
}

/// The render settings the options give (checked later, once, by
/// `FrameRequest::new`); the plan file of `--plan` is read and checked here.
pub fn settings(a: &FrameArgs) -> Result<RenderSettings> {
    let (base, base_shot) = match a.view {
        View::Portrait => (RenderSettings::default(), ShotPreset::Portrait),
        View::Study => (RenderSettings::study(), ShotPreset::Mid),
    };
    let distance = a
        .distance
        .unwrap_or_else(|| a.shot.unwrap_or(base_shot).distance_heads(a.fovy));
    let assignment = match (&a.assign, &a.plan) {
        (Some(rules), _) => Some(Assignment::Rules(rules.parse()?)),
        (None, Some(path)) => Some(Assignment::Plan(PlanFile::load(path)?)),
        (None, None) => None,
    };
    let mut s = RenderSettings {
        width: a.width,
        height: a.height,
        assignment,
        method: lookup(&a.method)?,
        options: a.method_options.0.clone(),
        transmittance: !a.no_transmittance,
        sss_region: a.sss_region,
        sss_region_tile: a.sss_region_tile,
        transmittance_profile: a.transmittance_profile,
        heads: a.heads,
        layout: a.layout,
        distance_heads: distance,
        fovy_deg: a.fovy,
        walk_heads: a.crowd_walked,
        ..base.clone()
    };
    s.light.azimuth_deg = a.light_azimuth.unwrap_or(base.light.azimuth_deg);
    s.light.elevation_deg = a.light_elevation.unwrap_or(base.light.elevation_deg);
    s.light.intensity = a.light_intensity;
    s.ambient = a.ambient.unwrap_or(base.ambient);
    s.exposure = a.exposure;
    s.shadow_size = a.shadow_size;
    s.aa = a.aa;
    s.post.bloom = a.bloom;
    s.post.aa_edges = a.aa_edges;
    s.post.smaa_preset = a.smaa_preset;
    s.msaa = a.msaa;
    s.lod_pixels = a.lod_pixels;
    s.texturing = a.texturing;
    Ok(s)
}

/// Loads the scene a source names (once per command).
pub fn load_scene(source: &SceneSource) -> Result<Scene> {
    let mut scene = source.load()?;
    if let Some(tone) = source.skin_tone {
        // The two-layer skin model's albedo (thesis ch. 7) for the tone.
        let m = &mut scene.head.material;
        if m.base_color.is_some() {
            anyhow::bail!("--skin-tone sets the albedo of an untextured skin; the scene's skin has an albedo texture, its own colour");
        }
        m.base_color_factor = crate::skin::colour::lut::tone_albedo(tone).map(|c| c as f32);
    }
    crate::checks::ran("scene");
    Ok(scene)
}

/// The device the options ask for.
pub fn context_desc(a: &FrameArgs) -> ContextDesc {
    ContextDesc {
        device: a.device.clone().unwrap_or_default(),
        validate: a.validate,
        ..Default::default()
    }
}

/// Opens the device the options ask for (after every check).
pub fn context(a: &FrameArgs) -> Result<Context> {
    Context::new(&context_desc(a))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::cli::{Cli, Command};
    use clap::{CommandFactory, FromArgMatches};

    fn parse(args: &[&str]) -> (FrameArgs, Given) {
        let m = Cli::command().try_get_matches_from(args).unwrap();
        let (_, sub) = m.subcommand().unwrap();
        let given = Given::of(sub);
        let Command::Render(r) = Cli::from_arg_matches(&m).unwrap().command else {
            panic!("not render")
        };
        (r.frame, given)
    }

    #[test]
    fn the_options_become_settings_and_a_source() {
        let (a, g) = parse(&[
            "dermis",
            "render",
            "--scene",
            "builtin:egg",
            "--width",
            "320",
            "--shot",
            "far",
            "--light-azimuth",
            "-20",
        ]);
        assert!(g.has("width") && g.has("scene") && !g.has("height"));
        let (src, s) = frame_settings(&a, &g).unwrap();
        assert_eq!(src.builtin(), Some("egg"));
        assert_eq!(s.width, 320);
        assert_eq!(s.light.azimuth_deg, -20.0);
        assert_eq!(s.distance_heads, ShotPreset::Far.distance_heads(s.fovy_deg));
        assert_eq!(
            s.light.elevation_deg,
            RenderSettings::default().light.elevation_deg
        );
    }

    #[test]
    fn settings_files_exclude_other_frame_options() {
        let (a, g) = parse(&["dermis", "render", "--settings", "x.json", "--width", "5"]);
        let e = frame_settings(&a, &g).unwrap_err().to_string();
        assert_eq!(
            e,
            "--width cannot be given with --settings: the file gives every frame setting"
        );
        // A method option too.
        let (a, g) = parse(&["dermis", "render", "--settings", "x.json", "--samples", "9"]);
        let e = frame_settings(&a, &g).unwrap_err().to_string();
        assert!(e.starts_with("--samples cannot"), "{e}");
    }
}
