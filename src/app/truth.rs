//! The frames a plan is scored against, rendered (issue 16 items 5 and 6):
//! the ground truth of the same frame with the character ids and the frame
//! with no SSS (`plan::score` scores a test frame against them), and one
//! frame's diffuse light. `plan-check` and `plan-motion` render with it.

use anyhow::{Context as _, Result};

use crate::eval::bands::{bands, BandInput};
use crate::method::{ground_truth, lookup, none, MethodOptions};
use crate::plan::score::Truth;
use crate::render::{RenderSettings, Renderer};
use crate::scene::Scene;
use crate::vk::context::Context;

/// Renders the ground truth of the frame `s` describes (with the
/// character ids, and the run's `--density` passed through: a crowd of
/// 64 at the default density is more surface than lavapipe holds) and
/// the same frame with no SSS, and finds the eval's bands.
pub fn render_truth(ctx: &Context, scene: &Scene, s: &RenderSettings) -> Result<Truth> {
    let mut gt_s = truth_settings(s)?;
    gt_s.character_ids = true;
    let gt = render(ctx, scene, &gt_s).context("ground truth")?;
    let none = render(ctx, scene, &with_method(s, none().name, &[])?).context("no SSS")?;
    let skin: Vec<bool> = gt.diffuse.iter().map(|p| p[3] > 0.0).collect();
    let band_input = BandInput::for_view(
        (gt.width as usize, gt.height as usize),
        &skin,
        &gt.depth,
        s.fovy_deg,
        scene.mm_per_unit,
    );
    Ok(Truth {
        bands: bands(&band_input),
        ids: gt
            .character_ids
            .clone()
            .context("the ground truth's character ids")?,
        diffuse: gt.diffuse,
        none: none.diffuse,
        characters: s.heads as usize,
    })
}

/// The ground truth's settings for the frame `s` describes: the method
/// options it reads kept (`--density`), every other option dropped.
pub fn truth_settings(s: &RenderSettings) -> Result<RenderSettings> {
    let density = s.options.given("density");
    let opts: Vec<(String, String)> = density
        .map(|d| ("density".into(), d.to_string()))
        .into_iter()
        .collect();
    with_method(s, ground_truth().name, &opts)
}

/// `base` with one method for every character.
pub fn with_method(
    base: &RenderSettings,
    method: &str,
    options: &[(String, String)],
) -> Result<RenderSettings> {
    let mut r = base.clone();
    r.assignment = None;
    r.method = lookup(method)?;
    let mut o = MethodOptions::default();
    for (k, v) in options {
        o.set(k, v.clone());
    }
    r.options = o;
    Ok(r)
}

/// Renders one frame of `s` and reads back its diffuse light (and with
/// `ids`, the character ids and depth).
pub fn render(ctx: &Context, scene: &Scene, s: &RenderSettings) -> Result<crate::render::Capture> {
    let mut r = Renderer::new(ctx, scene, s)?;
    r.capture(false)
}
