//! The merge of a frame of several methods: the composite takes each pixel
//! from its own method. Most methods write their result back into the diffuse
//! target on their own pixels (stencil-masked, in their region), so the
//! diffuse target is already the merged image for them; a group whose method
//! writes its result elsewhere (poisson's `out`) gets one stencil-masked copy
//! of its output into the diffuse target, limited to its region: the mixed
//! frame's own overhead, named `mix merge #N`. A single-method frame has no
//! merge: its composite reads the method's output, as before groups.

use anyhow::Result;
use ash::vk;

use super::groups::GroupMethod;
use crate::graph::work::{Filter, PassRole};
use crate::graph::{ImageId, Pass, Resources};
use crate::method::screen::{fetch, masked_pass, Masked};
use crate::method::{skin_stencil_test, FrameTargets, FrameView};
use crate::vk::context::Context;
use crate::vk::guard::Destroy;
use crate::vk::pipeline::{Bind, DescriptorPool, GraphicsDesc, Pipeline};

pub const MERGE_SHADER: &str = "composite_merge.frag";

/// The merge pipeline and one descriptor set per group that needs a copy.
#[derive(Default)]
pub struct Merge {
    pipeline: Pipeline,
    /// (group index, set reading its output): the groups are known when the
    /// pipeline is made (the passes declare their usages before the images
    /// exist), the sets are written by `bind`.
    sets: Vec<(usize, vk::DescriptorSet)>,
}

/// Whether group `g`'s result must be copied into the diffuse target.
pub fn needs_merge(g: &GroupMethod, targets: &FrameTargets) -> bool {
    !g.is_none() && g.method.output() != targets.diffuse
}

impl Merge {
    /// The pipeline and the groups that need a copy (only a frame of several
    /// groups with one that needs a copy builds one).
    pub fn new(
        ctx: &Context,
        res: &Resources,
        targets: &FrameTargets,
        groups: &[GroupMethod],
    ) -> Result<Merge> {
        let ds = res.format(targets.depth_stencil);
        let mut desc =
            GraphicsDesc::fullscreen("mix merge", MERGE_SHADER, res.format(targets.diffuse));
        desc.depth_format = Some(ds);
        desc.stencil_format = Some(ds);
        desc.stencil = Some(skin_stencil_test());
        Ok(Merge {
            pipeline: Pipeline::graphics(ctx, &desc)?,
            sets: groups
                .iter()
                .filter(|g| needs_merge(g, targets))
                .map(|g| (g.spec.index, vk::DescriptorSet::null()))
                .collect(),
        })
    }

    /// One set per group that needs a copy, reading its output.
    pub fn bind(
        &mut self,
        ctx: &Context,
        pool: &DescriptorPool,
        res: &Resources,
        targets: &FrameTargets,
        groups: &[GroupMethod],
    ) -> Result<()> {
        for (i, set) in &mut self.sets {
            let Some(g) = groups.iter().find(|g| g.spec.index == *i) else {
                continue;
            };
            debug_assert!(needs_merge(g, targets));
            *set = pool.write_set(
                ctx,
                &self.pipeline,
                0,
                &[("groupTex", Bind::Texture(res.view(g.method.output())))],
            )?;
        }
        Ok(())
    }

    /// The copy of group `g`'s output (`output`) into the diffuse target,
    /// against `f` (the group's region and stencil code).
    pub fn pass<'a>(
        &'a self,
        f: &FrameView<'a, '_>,
        g: usize,
        output: ImageId,
    ) -> Option<Pass<'a>> {
        let &(_, set) = self.sets.iter().find(|(i, _)| *i == g)?;
        let mut p = masked_pass(
            f,
            Masked {
                name: format!("mix merge #{g}"),
                shader: MERGE_SHADER,
                loop_trips: Vec::new(),
                pipeline: &self.pipeline,
                set,
                reads: vec![output],
                fetches: vec![fetch(f.res, output, "groupTex", Filter::Point, 1.0)],
                targets: vec![(f.targets.diffuse, false)],
                stencil: true,
                depth_test: false,
            },
            |_, _| {},
        );
        debug_assert_eq!(p.role, PassRole::Sss);
        p.group = Some(g);
        Some(p)
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.pipeline.destroy(ctx);
    }
}

impl Destroy for Merge {
    fn destroy(&mut self, ctx: &Context) {
        Merge::destroy(self, ctx)
    }
}
