//! The merge of a frame of several methods: the composite takes each pixel
//! from its own method. Most methods write their result back into the diffuse
//! target on their own pixels (stencil-masked, in their region), so the
//! diffuse target is already the merged image for them; a group whose method
//! writes its result elsewhere (poisson's `out`) gets one stencil-masked copy
//! of its output into the diffuse target, limited to its region: the mixed
//! frame's own overhead, named `mix merge #N`. A single-method frame has no
//! merge: its composite reads the method's output, as before groups.
//!
//! A fading character's group (`fade::FadeMethod`) is blended last: its old
//! setting's result drawn over the diffuse target, stencil-masked to its code
//! and limited to the old instance's region, with fixed-function blending by
//! the constant `weight` (`src * w + dst * (1 - w)`, the new setting's result
//! being what the target holds by then): `#N fade blend`.

use anyhow::Result;

use super::GroupMethod;
use crate::graph::work::{Filter, PassRole};
use crate::graph::{Binding, GraphSet, ImageId, Pass, Resources};
use crate::method::screen::{fetch, masked_pass, Masked};
use crate::method::{skin_stencil_test, FrameTargets, FrameView};
use crate::vk::context::Context;
use crate::vk::guard::{Destroy, Guard};
use crate::vk::pipeline::{Blend, DescriptorPool, GraphicsDesc, Pipeline};

pub const MERGE_SHADER: &str = "composite_merge.frag";

/// The merge pipelines (the copy's, the fade's blend) and one descriptor set
/// per group that needs each.
#[derive(Default)]
pub struct Merge {
    pipeline: Pipeline,
    /// (group index, set reading its output): the groups are known when the
    /// pipeline is made (the passes declare their usages before the images
    /// exist), the sets are written by `bind`.
    sets: Vec<(usize, GraphSet)>,
    fade_pipeline: Pipeline,
    /// (group index, set reading its old setting's result).
    fade_sets: Vec<(usize, GraphSet)>,
}

/// Whether group `g`'s result must be copied into the diffuse target.
pub fn needs_merge(g: &GroupMethod, targets: &FrameTargets) -> bool {
    !g.is_none() && g.method.output() != targets.diffuse
}

/// Whether a frame of `groups` needs a [`Merge`]: a copy or a fade.
pub fn needs_any(groups: &[GroupMethod], targets: &FrameTargets) -> bool {
    groups
        .iter()
        .any(|g| needs_merge(g, targets) || g.fade.is_some())
}

impl Merge {
    /// The pipelines the groups need: the copy's where a group's result lies
    /// apart, the blend's where a character fades.
    pub fn new(
        ctx: &Context,
        res: &Resources,
        targets: &FrameTargets,
        groups: &[GroupMethod],
    ) -> Result<Merge> {
        let ds = res.format(targets.depth_stencil);
        let desc = |name: &str, blend: Blend| {
            let mut d = GraphicsDesc::fullscreen(name, MERGE_SHADER, res.format(targets.diffuse));
            d.depth_format = Some(ds);
            d.stencil_format = Some(ds);
            d.stencil = Some(skin_stencil_test());
            d.blend = blend;
            d
        };
        let mut m = Guard::new(ctx, Merge::default());
        let copies: Vec<&GroupMethod> = groups.iter().filter(|g| needs_merge(g, targets)).collect();
        let fades: Vec<(usize, ImageId)> = groups
            .iter()
            .filter_map(|g| Some((g.spec.index, g.fade.as_ref()?.method.output())))
            .collect();
        if !copies.is_empty() {
            m.pipeline = Pipeline::graphics(ctx, &desc("mix merge", Blend::None))?;
        }
        if !fades.is_empty() {
            m.fade_pipeline = Pipeline::graphics(ctx, &desc("fade blend", Blend::ConstantMix(0)))?;
        }
        let set = |pipeline: &Pipeline, image| {
            GraphSet::new(
                res,
                pipeline,
                0,
                vec![("groupTex", Binding::Sampled(image))],
            )
        };
        m.sets = copies
            .iter()
            .map(|g| (g.spec.index, set(&m.pipeline, g.method.output())))
            .collect();
        m.fade_sets = fades
            .into_iter()
            .map(|(i, old)| (i, set(&m.fade_pipeline, old)))
            .collect();
        Ok(m.keep())
    }

    /// Writes the sets (once the images exist).
    pub fn bind(&mut self, ctx: &Context, pool: &DescriptorPool, res: &Resources) -> Result<()> {
        for (_, set) in &mut self.sets {
            set.write(ctx, pool, res, &self.pipeline)?;
        }
        for (_, set) in &mut self.fade_sets {
            set.write(ctx, pool, res, &self.fade_pipeline)?;
        }
        Ok(())
    }

    /// The blend of group `g`'s old setting's result (`old`) into the diffuse
    /// target by `weight`, against `f` (the old instance's region, the group's
    /// stencil code).
    pub fn fade_pass<'a>(
        &'a self,
        f: &FrameView<'a, '_>,
        g: usize,
        old: ImageId,
        weight: f64,
    ) -> Option<Pass<'a>> {
        let (_, set) = self.fade_sets.iter().find(|(i, _)| *i == g)?;
        let name = format!("#{g} fade blend");
        Some(draw_into_diffuse(
            f,
            g,
            name,
            (&self.fade_pipeline, set),
            old,
            Some(weight as f32),
        ))
    }

    /// The copy of group `g`'s output (`output`) into the diffuse target,
    /// against `f` (the group's region and stencil code).
    pub fn pass<'a>(
        &'a self,
        f: &FrameView<'a, '_>,
        g: usize,
        output: ImageId,
    ) -> Option<Pass<'a>> {
        let (_, set) = self.sets.iter().find(|(i, _)| *i == g)?;
        let name = format!("mix merge #{g}");
        let mut p = draw_into_diffuse(f, g, name, (&self.pipeline, set), output, None);
        p.merge = true;
        Some(p)
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.pipeline.destroy(ctx);
        self.fade_pipeline.destroy(ctx);
    }
}

impl Destroy for Merge {
    fn destroy(&mut self, ctx: &Context) {
        Merge::destroy(self, ctx)
    }
}

/// `image` drawn into the diffuse target on group `g`'s pixels (stencil-tested
/// on its code, in `f`'s region) with `pipeline`: copied, or with `blend` the
/// constant that mixes it in (`src * c + dst * (1 - c)`).
fn draw_into_diffuse<'a>(
    f: &FrameView<'a, '_>,
    g: usize,
    name: String,
    (pipeline, set): (&'a Pipeline, &'a GraphSet),
    image: ImageId,
    blend: Option<f32>,
) -> Pass<'a> {
    let mut p = masked_pass(
        f,
        Masked {
            name,
            shader: MERGE_SHADER,
            loop_trips: Vec::new(),
            pipeline,
            set,
            fetches: vec![fetch(f.res, image, "groupTex", Filter::Point, 1.0)],
            targets: vec![(f.targets.diffuse, blend.is_some())],
            stencil: true,
            depth_test: false,
        },
        move |ctx, cmd| {
            if let Some(c) = blend {
                unsafe { ctx.device.cmd_set_blend_constants(cmd, &[c, c, c, 1.0]) }
            }
        },
    );
    debug_assert_eq!(p.role, PassRole::Sss);
    p.group = Some(g);
    p
}
