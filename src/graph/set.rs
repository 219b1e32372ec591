//! Descriptor sets of the graph: a set states, when it is made, which frame
//! images and buffers it binds and how (sampled, as storage); declaring it
//! on a pass ([`Pass::set`](super::Pass::set)) declares them all, in that
//! order, with the access kinds the set's pipeline implies (a graphics
//! pipeline's reads are fragment-stage, a compute pipeline's compute-stage).
//! The set is written once its images exist (at bind time, not per frame),
//! from the same list: what a pass samples through a set is what it
//! declares, one fact stated once.

use anyhow::{ensure, Result};
use ash::vk;

use super::resources::{BufferId, ImageId, Resources};
use crate::vk::barrier::AccessKind;
use crate::vk::context::Context;
use crate::vk::pipeline::{Bind, DescriptorPool, Pipeline};

/// How a shader uses a storage image or buffer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Storage {
    Read,
    /// Every element it covers is written, none read.
    Write,
    ReadWrite,
}

/// One binding of a set, by the shader's variable name.
#[derive(Clone, Copy, Debug)]
pub enum Binding {
    /// A frame image sampled through the view of its level.
    Sampled(ImageId),
    /// A frame image sampled through one view of all its levels (every
    /// level is declared).
    SampledLevels(ImageId),
    /// An sRGB frame image sampled through its UNORM view (its encoded
    /// values; `Resources::request_unorm_view`).
    SampledUnorm(ImageId),
    /// The stencil aspect of a depth/stencil frame image, sampled (a
    /// `utexture2D`: the compute path's skin mask).
    SampledStencil(ImageId),
    /// The depth aspect of a depth/stencil frame image, sampled (the
    /// compute path's depth-based Gaussian skipping reads the depth the
    /// fragment path's depth test compares).
    SampledDepth(ImageId),
    /// A frame image as a storage image.
    StorageImage(ImageId, Storage),
    /// `size` bytes from `offset` of a tracked buffer, as a storage buffer.
    StorageBuffer {
        id: BufferId,
        offset: u64,
        size: u64,
        storage: Storage,
    },
    /// Anything that is no frame resource: samplers, uniform buffers, static
    /// textures uploaded once.
    Fixed(Bind),
}

/// A descriptor set whose frame resources the graph knows.
/// (`Default` is the null set of a method not set up yet.)
#[derive(Debug, Default)]
pub struct GraphSet {
    pipeline: String,
    index: u32,
    binds: Vec<(&'static str, Binding)>,
    /// What a pass declaring the set declares, in binding order, once each.
    pub(super) images: Vec<(ImageId, AccessKind)>,
    pub(super) buffers: Vec<(BufferId, AccessKind)>,
    pub(super) raw: vk::DescriptorSet,
}

impl GraphSet {
    /// Set `index` of `pipeline` with `binds` (written by [`GraphSet::write`]
    /// once the images exist).
    pub fn new(
        res: &Resources,
        pipeline: &Pipeline,
        index: u32,
        binds: Vec<(&'static str, Binding)>,
    ) -> Self {
        let compute = pipeline.bind_point == vk::PipelineBindPoint::COMPUTE;
        let mut images = Vec::new();
        let mut buffers = Vec::new();
        for &(_, b) in &binds {
            match b {
                Binding::Sampled(id)
                | Binding::SampledUnorm(id)
                | Binding::SampledStencil(id)
                | Binding::SampledDepth(id) => {
                    images.push((id, sampled(compute)));
                }
                Binding::SampledLevels(id) => {
                    images.extend(res.levels(id).into_iter().map(|l| (l, sampled(compute))));
                }
                Binding::StorageImage(id, s) => images.push((id, storage(compute, s, pipeline))),
                Binding::StorageBuffer { id, storage: s, .. } => {
                    buffers.push((id, storage(compute, s, pipeline)));
                }
                Binding::Fixed(_) => {}
            }
        }
        dedup(&mut images);
        dedup(&mut buffers);
        GraphSet {
            pipeline: pipeline.name.clone(),
            index,
            binds,
            images,
            buffers,
            raw: vk::DescriptorSet::null(),
        }
    }

    /// Whether a pass binding the set reads `id` through it (a stage handed
    /// `id` checks that the set it stated at set-up reads what it is given).
    pub fn reads(&self, id: ImageId) -> bool {
        self.images.iter().any(|&(i, a)| i == id && !a.is_write())
    }

    /// Writes the set (once, after the images exist) for `pipeline`, the one
    /// it was made for.
    pub fn write(
        &mut self,
        ctx: &Context,
        pool: &DescriptorPool,
        res: &Resources,
        pipeline: &Pipeline,
    ) -> Result<()> {
        ensure!(
            pipeline.name == self.pipeline,
            "a set of pipeline '{}' written for '{}'",
            self.pipeline,
            pipeline.name
        );
        let binds: Vec<(&str, Bind)> = self
            .binds
            .iter()
            .map(|&(name, b)| {
                let bind = match b {
                    Binding::Sampled(id) | Binding::StorageImage(id, _) => {
                        Bind::Texture(res.view(id))
                    }
                    Binding::SampledLevels(id) => Bind::Texture(res.image(id).chain_view),
                    Binding::SampledUnorm(id) => Bind::Texture(res.unorm_view(id)),
                    Binding::SampledStencil(id) => Bind::Texture(res.stencil_view(id)),
                    Binding::SampledDepth(id) => Bind::Texture(res.image(id).sampled_view()),
                    Binding::StorageBuffer {
                        id, offset, size, ..
                    } => Bind::Range {
                        buffer: res.buffer(id),
                        offset,
                        size,
                    },
                    Binding::Fixed(b) => b,
                };
                (name, bind)
            })
            .collect();
        self.raw = pool.write_set(ctx, pipeline, self.index, &binds)?;
        Ok(())
    }
}

fn sampled(compute: bool) -> AccessKind {
    if compute {
        AccessKind::ComputeSampledRead
    } else {
        AccessKind::FragmentSampledRead
    }
}

/// The access kind of a storage use in `pipeline`'s stage. The fragment
/// stage has no write-only kind: a fragment shader that writes storage
/// without reading it is not one dermis has (a programmer error).
fn storage(compute: bool, s: Storage, pipeline: &Pipeline) -> AccessKind {
    match (compute, s) {
        (true, Storage::Read) => AccessKind::ComputeStorageRead,
        (true, Storage::Write) => AccessKind::ComputeStorageWrite,
        (true, Storage::ReadWrite) => AccessKind::ComputeStorageReadWrite,
        (false, Storage::Read) => AccessKind::FragmentStorageRead,
        (false, Storage::ReadWrite) => AccessKind::FragmentStorageReadWrite,
        (false, Storage::Write) => panic!(
            "pipeline '{}': a fragment shader's write-only storage has no access kind",
            pipeline.name
        ),
    }
}

/// Keeps the first of each equal entry (a set may bind one image twice, as
/// FXAA's colour and luma views).
fn dedup<T: PartialEq + Copy>(v: &mut Vec<T>) {
    let mut seen = Vec::with_capacity(v.len());
    v.retain(|x| {
        let new = !seen.contains(x);
        if new {
            seen.push(*x);
        }
        new
    });
}
