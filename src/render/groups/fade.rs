//! A character cross-fading between two settings (`mix::Fade`, a re-planned
//! sequence's switch): its group also holds its old setting's instance
//! ([`FadeMethod`]), built over the same character and stencil code on the
//! frame's targets with the diffuse target replaced by a copy of it taken
//! before any group writes in place (`#N fade keep`), so that it reads the
//! light before SSS as its own group would. The groups' stage
//! (`passes.rs`) records the keep, the old instance's passes (named
//! `#N fade ...`) and the blend of its result into the diffuse target by the
//! fade's weight (`merge.rs`, `#N fade blend`).

use anyhow::{Context as _, Result};
use ash::vk;
use glam::Mat4;

use super::region::{region_for, scissors, skin_region};
use super::FadeSpec;
use crate::graph::{ImageDesc, ImageId, Pass, Resources};
use crate::method::region::PixelRect;
use crate::method::screen::seed_copy;
use crate::method::{FrameTargets, FrameView, MethodSetup, SssMethod};
use crate::render::frame::Frame;
use crate::scene::Scene;
use crate::vk::context::Context;

/// The old setting of a fading character's group, built over the keep.
pub struct FadeMethod {
    pub spec: FadeSpec,
    /// The copy of the diffuse target it reads and (most methods) writes in place.
    pub keep: ImageId,
    /// The frame's targets with `diffuse` = `keep`: what it was built on and
    /// its passes are recorded against.
    pub targets: FrameTargets,
    pub method: Box<dyn SssMethod>,
    /// Its region (its own reach over the character): where the keep is
    /// copied, its passes work and its result is blended.
    pub region_px: Vec<PixelRect>,
    pub scissors: Vec<vk::Rect2D>,
}

impl FadeMethod {
    /// The old setting of group `index`'s fading character: a keep of the
    /// diffuse target (its levels too: a method that builds a mip chain
    /// builds it on its own input) and the old method built on it under
    /// `#N fade `.
    pub fn build(
        ctx: &Context,
        res: &mut Resources,
        frame: &Frame,
        scene: &Scene,
        index: usize,
        spec: FadeSpec,
        // The fading characters' models and frame indices.
        (instances, characters): (&[Mat4], &[usize]),
    ) -> Result<FadeMethod> {
        let diffuse = frame.targets.diffuse;
        let depth_stencil_format = res.format(frame.targets.depth_stencil);
        res.set_name_prefix(&format!("#{index} fade "));
        let keep = res.declare(
            ImageDesc::new("keep", res.extent(diffuse), res.format(diffuse))
                .with_levels(res.levels(diffuse).len() as u32),
        );
        let targets = FrameTargets {
            diffuse: keep,
            ..frame.targets
        };
        let method = (spec.entry.build)(&mut MethodSetup {
            ctx,
            res,
            targets: &targets,
            samplers: &frame.samplers,
            options: spec.entry.opts(&spec.options),
            view: frame.view_info(),
            depth_stencil_format,
            scene,
            instances,
            characters,
            frame_binds: frame.frame_binds(),
        })
        .with_context(|| format!("setting up the fade from {}", spec.label));
        res.set_name_prefix("");
        let method = method?;
        // No SSS reaches nowhere: its result is the keep itself, needed only
        // on the character's skin.
        let region = if spec.entry.no_sss {
            skin_region(frame, scene, instances)
        } else {
            region_for(frame, scene, &*method, instances)
        };
        let mut f = FadeMethod {
            spec,
            keep,
            targets,
            method,
            region_px: Vec::new(),
            scissors: Vec::new(),
        };
        f.set_region(region);
        Ok(f)
    }

    pub fn set_region(&mut self, px: Vec<PixelRect>) {
        self.scissors = scissors(&px);
        self.region_px = px;
    }

    /// What its passes are built against: the keep as the diffuse target,
    /// its own region, its group's stencil code (`group`: the group's view).
    pub fn view<'a, 'r>(&'a self, group: &FrameView<'a, 'r>) -> FrameView<'a, 'r> {
        FrameView {
            targets: &self.targets,
            region: &self.scissors,
            ..*group
        }
    }

    /// The keep of the light before SSS (`#N fade keep`), copied from the
    /// diffuse target in its region before any group writes it in place.
    pub fn keep_pass<'a>(&'a self, group: &FrameView<'a, '_>, index: usize) -> Pass<'a> {
        let mut p = seed_copy(
            &format!("#{index} fade keep"),
            &self.view(group),
            group.targets.diffuse,
            &self.scissors,
            &[self.keep],
        );
        p.group = Some(index);
        p
    }

    /// Its old setting's passes, named `#N fade ...`.
    pub fn passes<'a>(&'a self, group: &FrameView<'a, '_>, index: usize) -> Vec<Pass<'a>> {
        let mut passes = self.method.passes(&self.view(group));
        for p in &mut passes {
            p.group = Some(index);
            p.name = format!("#{index} fade {}", p.name);
        }
        passes
    }
}
