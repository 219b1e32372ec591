//! A frame to render, checked once before any device opens (issue 27): its
//! settings validated and its character groups resolved against the scene.
//! The renderer and the run take a [`FrameRequest`] and check nothing of it
//! again; only what the device alone knows (its largest image) is checked
//! when the renderer is built on it.

use anyhow::Result;
use serde::{Deserialize, Serialize};

use super::groups::{group_specs, specs_mixed, GroupSpec};
use super::settings::RenderSettings;
use crate::scene::source::SceneSource;
use crate::scene::Scene;

/// Settings that passed [`RenderSettings::validate`] (every check that needs
/// neither a scene nor a device), checked before the scene loads so that a
/// bad number is reported before a file is read.
#[derive(Clone, Debug)]
pub struct CheckedSettings(RenderSettings);

impl CheckedSettings {
    pub fn new(settings: RenderSettings) -> Result<Self> {
        settings.validate()?;
        crate::checks::ran("settings");
        Ok(CheckedSettings(settings))
    }

    pub fn get(&self) -> &RenderSettings {
        &self.0
    }
}

/// A checked frame: a scene, settings that passed
/// [`RenderSettings::validate`], and the groups they resolve to in it.
/// The only ways to one are [`FrameRequest::new`] and [`FrameRequest::of`].
#[derive(Clone, Debug)]
pub struct FrameRequest<'s> {
    scene: &'s Scene,
    settings: RenderSettings,
    groups: Vec<GroupSpec>,
}

impl<'s> FrameRequest<'s> {
    /// Validates `settings` and resolves their groups in `scene`: every
    /// error is one line naming the setting, rule or plan entry at fault.
    pub fn new(scene: &'s Scene, settings: RenderSettings) -> Result<Self> {
        Self::of(scene, CheckedSettings::new(settings)?)
    }

    /// Resolves the groups of checked settings in `scene`.
    pub fn of(scene: &'s Scene, settings: CheckedSettings) -> Result<Self> {
        let settings = settings.0;
        check_in_view(scene, &settings)?;
        let groups = group_specs(scene, &settings)?;
        check_steps(scene, &groups)?;
        crate::checks::ran("groups");
        Ok(FrameRequest {
            scene,
            settings,
            groups,
        })
    }

    pub fn scene(&self) -> &'s Scene {
        self.scene
    }

    pub fn settings(&self) -> &RenderSettings {
        &self.settings
    }

    /// The character groups: one in a single-method frame.
    pub fn groups(&self) -> &[GroupSpec] {
        &self.groups
    }

    /// A frame of several methods (more than one group, or a fade).
    pub fn mixed(&self) -> bool {
        specs_mixed(&self.groups)
    }

    /// The frame with the character-id pass added (what `groups.png` of a
    /// frame of several methods needs: it changes no image), where the
    /// frame can have it: `None` for a multisampled frame, whose ids would
    /// be drawn against a depth resolved from one sample
    /// (`RenderSettings::validate` refuses `--character-ids` there).
    pub fn with_character_ids(&self) -> Option<Self> {
        (self.settings.msaa == 1).then(|| FrameRequest {
            settings: RenderSettings {
                character_ids: true,
                ..self.settings.clone()
            },
            ..self.clone()
        })
    }
}

/// Refuses `--time-step` with a method that reads the characters' meshes
/// once, as it is built (it would draw frame 0's pose under every later
/// frame's geometry).
fn check_steps(scene: &Scene, groups: &[GroupSpec]) -> Result<()> {
    if scene.tracks.as_ref().and_then(|t| t.step).is_none() {
        return Ok(());
    }
    let entries = groups.iter().map(|g| g.entry).chain(
        groups
            .iter()
            .filter_map(|g| g.fade.as_ref().map(|f| f.entry)),
    );
    for e in entries {
        if let Some(why) = e.poses_once {
            anyhow::bail!(
                "--time-step cannot be given with {}: {why} (render each time with --time instead)",
                e.name
            );
        }
    }
    Ok(())
}

/// Refuses a frame that would show none of its characters: the framing
/// (`render`'s shot) puts every triangle of every character outside the
/// view (a model framed by a stray part, a scale far off, a crowd walked
/// past the camera), which would render a frame of backdrop and exit 0.
/// A character whose box misses the view is skipped at once; the first
/// whose triangles reach it ends the search.
fn check_in_view(scene: &Scene, settings: &RenderSettings) -> Result<()> {
    use crate::scene::casters::{in_view, mesh_in_view};
    use crate::scene::crowd_geometry::{drawn_bounds, turned};
    let framing = crate::scene::framing::frame(scene, &super::groups::shot(scene, settings));
    let aspect = settings.width as f32 / settings.height.max(1) as f32;
    let view_proj = framing.camera.view_proj(aspect);
    let drawn = drawn_bounds(scene);
    let seen = turned(scene, framing.instances).iter().any(|m| {
        in_view(&view_proj, &drawn.transformed(m))
            && std::iter::once(&scene.head)
                .chain(&scene.parts)
                .any(|o| mesh_in_view(&view_proj, m, &o.mesh))
    });
    crate::checks::ran("in view");
    if !seen {
        let c = framing.camera;
        anyhow::bail!(
            "no character is in view: none of their triangles reaches the frame (the camera at {:.3?} looks at {:.3?}); check the model's scale (--mm-per-unit) and the shot (--distance, --crowd-walked)",
            c.eye.to_array(),
            c.target.to_array()
        );
    }
    Ok(())
}

/// Everything a frame is made from, as `report.json` records it (its
/// `settings`) and `dermis render --settings` reads it back: the scene's
/// source and the render settings, both whole, by serialisation.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrameSettings {
    /// `None`: a scene built in code (a test), which no file names.
    pub scene: Option<SceneSource>,
    pub render: RenderSettings,
}
