//! The planner's inputs frame after frame (issue 16 item 6: "plan time per
//! frame reported; for 64 characters it is far below a frame"): what does
//! not change between frames is built once (the head's measures, its skin
//! patches, every setting's fixed cost) and what does is cheap (the
//! characters from [`SkinPatches`], their parts from the [`PriceGrid`]).
//! `dermis plan-motion` re-plans with it; `dermis plan` and `plan-check`,
//! which plan one frame, keep the exact rasterisation and direct prices of
//! [`super::cli::characters`] and [`super::cli::setting_costs`]. No device:
//! the pure parts are [`SkinPatches`] and [`PriceGrid`]; this file only
//! places the frame as `render` does. docs/plan-over-time.md gives its times and its error against the
//! exact inputs.

use std::time::Instant;

use super::character::{from_visible, FrameView};
use super::cost::SettingModel;
use super::over_time::FrameInput;
use super::pipeline::{atlas_mm, with_regions};
use super::price_grid::PriceGrid;
use super::skin_patches::{SkinPatches, View};
use crate::budget::profile::Profile;
use crate::render::RenderSettings;
use crate::scene::framing::frame_sized;
use crate::scene::mesh::Mesh;
use crate::scene::{HeadSize, Scene};

/// Builds one [`FrameInput`] per frame for frames of one size on one profile.
pub struct FrameInputs<'a> {
    scene: &'a Scene,
    size: HeadSize,
    /// `None`: the head is not skin (no character has skin pixels).
    patches: Option<SkinPatches>,
    reference: &'a SettingModel,
    grid: PriceGrid<'a>,
    atlas_mm: f64,
    width: u32,
    height: u32,
    /// Time the set-up took (ms): measuring the head, binning its patches,
    /// pricing every setting's fixed cost.
    pub setup_ms: f64,
}

impl<'a> FrameInputs<'a> {
    /// Inputs for frames of `width` x `height` of `scene` priced on `profile`.
    pub fn new(
        scene: &'a Scene,
        models: &'a [SettingModel],
        reference: &'a SettingModel,
        profile: &'a Profile,
        width: u32,
        height: u32,
    ) -> FrameInputs<'a> {
        let t = Instant::now();
        let patches = scene.head.material.skin.then(|| {
            // Skin inside a closed part (behind an eyeball) is never seen.
            let parts: Vec<&Mesh> = scene.parts.iter().map(|p| &p.mesh).collect();
            let skin = crate::scene::enclosed::visible_skin(&scene.head.mesh, &parts);
            SkinPatches::of(&skin, scene.mm_per_unit)
        });
        let mut inputs = FrameInputs {
            scene,
            size: scene.head_size(),
            patches,
            reference,
            grid: PriceGrid::new(models, reference, profile, width, height),
            atlas_mm: atlas_mm(scene),
            width,
            height,
            setup_ms: 0.0,
        };
        inputs.setup_ms = t.elapsed().as_secs_f64() * 1e3;
        inputs
    }

    /// Prices the grid for characters between `x_lo` and `x_hi` px/mm at
    /// once ([`PriceGrid::fill`]), so that later frames price nothing; its
    /// time is added to [`FrameInputs::setup_ms`].
    pub fn fill(&mut self, x_lo: f64, x_hi: f64) {
        let t = Instant::now();
        let head_mm = f64::from(self.size.height * self.scene.mm_per_unit);
        self.grid.fill(x_lo, x_hi, head_mm);
        self.setup_ms += t.elapsed().as_secs_f64() * 1e3;
    }

    /// [`FrameInputs::fill`] over every scale at which a character can take
    /// a setting: from where the scattering's reach spans one pixel (below
    /// it the planner gives none) to a head twice the frame's height.
    pub fn fill_scene(&mut self) {
        let head_mm = f64::from(self.size.height * self.scene.mm_per_unit).max(1e-9);
        let lo = 1.0 / super::choose::scatter_reach_mm();
        let hi = 2.0 * f64::from(self.height) / head_mm;
        self.fill(lo, hi.max(lo));
    }

    /// Grid points priced so far (see [`PriceGrid::priced`]).
    pub fn priced(&self) -> usize {
        self.grid.priced
    }

    /// The inputs of the frame `s` describes (its size must be the one given
    /// to [`FrameInputs::new`]; the region tiles are left empty: re-planning
    /// prices the additive parts, not the merged regions).
    pub fn frame(&mut self, s: &RenderSettings) -> FrameInput {
        debug_assert_eq!((s.width, s.height), (self.width, self.height));
        let t = Instant::now();
        let shot = crate::render::groups::shot(self.scene, s);
        let framing = frame_sized(self.scene, &shot, &self.size);
        let cam = framing.camera;
        let (w, h) = (self.width, self.height);
        let visible: Vec<(f64, [u32; 4])> = match &self.patches {
            Some(p) => {
                let v = View {
                    view_proj: cam.view_proj(w as f32 / h as f32),
                    eye: cam.eye,
                    width: w,
                    height: h,
                    focal_px: h as f32 / (2.0 * (0.5 * cam.fovy_rad).tan()),
                };
                p.estimate(&framing.instances, &v)
                    .into_iter()
                    .map(|e| (e.pixels, e.rect))
                    .collect()
            }
            None => vec![(0.0, [0; 4]); framing.instances.len()],
        };
        let view = FrameView {
            framing: &framing,
            width: w,
            height: h,
            light_dir: shot.light_dir,
            shadow_size: s.shadow_size,
        };
        let mut characters = from_visible(self.scene, &self.size, &view, &visible);
        with_regions(&mut characters, self.reference, Vec::new());
        let t1 = Instant::now();
        let at: Vec<(f64, f64)> = characters
            .iter()
            .map(|c| (c.px_per_mm, c.skin_pixels))
            .collect();
        let costs = self.grid.costs(&at, self.atlas_mm);
        FrameInput {
            characters,
            costs,
            inputs_ms: t.elapsed().as_secs_f64() * 1e3,
            costs_ms: t1.elapsed().as_secs_f64() * 1e3,
        }
    }
}
