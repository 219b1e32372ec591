//! The pass graph: a pass is a name, the resources it reads and writes with their
//! access kinds, and a record closure. The executor remembers each resource's last
//! access, derives the barriers from (previous, next) with the one table in
//! `vk::barrier`, batches them into one call per pass, and wraps each pass in a
//! debug label, timestamps and a fragment-invocation query.

pub mod work;

use ash::vk;

use crate::vk::barrier::{AccessKind, ResourceState};
use crate::vk::context::Context;
use crate::vk::profiler::Profiler;

/// Index of an image registered with [`Resources`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ImageId(pub usize);
/// Index of a buffer registered with [`Resources`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct BufferId(pub usize);

/// What the graph needs to know of an image to emit its barriers.
#[derive(Clone, Debug)]
pub struct ImageEntry {
    pub name: String,
    pub raw: vk::Image,
    pub range: vk::ImageSubresourceRange,
    pub state: ResourceState,
}

#[derive(Clone, Debug)]
pub struct BufferEntry {
    pub name: String,
    pub raw: vk::Buffer,
    pub state: ResourceState,
}

/// Tracked resources and their last access. Lives as long as the renderer, so
/// the state carries over from frame to frame.
#[derive(Default, Debug)]
pub struct Resources {
    pub images: Vec<ImageEntry>,
    pub buffers: Vec<BufferEntry>,
}

impl Resources {
    pub fn add_image(
        &mut self,
        name: &str,
        raw: vk::Image,
        range: vk::ImageSubresourceRange,
    ) -> ImageId {
        self.images.push(ImageEntry {
            name: name.into(),
            raw,
            range,
            state: ResourceState::default(),
        });
        ImageId(self.images.len() - 1)
    }

    pub fn add_buffer(&mut self, name: &str, raw: vk::Buffer) -> BufferId {
        self.buffers.push(BufferEntry {
            name: name.into(),
            raw,
            state: ResourceState::default(),
        });
        BufferId(self.buffers.len() - 1)
    }

    /// The barriers that take every listed resource from its last access to
    /// the given one, and the state update. Pure: tested without a GPU.
    pub fn plan(
        &mut self,
        images: &[(ImageId, AccessKind)],
        buffers: &[(BufferId, AccessKind)],
    ) -> (
        Vec<vk::ImageMemoryBarrier2<'static>>,
        Vec<vk::BufferMemoryBarrier2<'static>>,
    ) {
        let mut ib = Vec::new();
        for &(id, next) in images {
            let e = &mut self.images[id.0];
            if let Some(p) = e.state.plan(next, true) {
                ib.push(
                    vk::ImageMemoryBarrier2::default()
                        .src_stage_mask(p.src_stage)
                        .src_access_mask(p.src_access)
                        .dst_stage_mask(p.dst_stage)
                        .dst_access_mask(p.dst_access)
                        .old_layout(p.old_layout)
                        .new_layout(p.new_layout)
                        .image(e.raw)
                        .subresource_range(e.range),
                );
            }
        }
        let mut bb = Vec::new();
        for &(id, next) in buffers {
            let e = &mut self.buffers[id.0];
            if let Some(p) = e.state.plan(next, false) {
                bb.push(
                    vk::BufferMemoryBarrier2::default()
                        .src_stage_mask(p.src_stage)
                        .src_access_mask(p.src_access)
                        .dst_stage_mask(p.dst_stage)
                        .dst_access_mask(p.dst_access)
                        .buffer(e.raw)
                        .offset(0)
                        .size(vk::WHOLE_SIZE),
                );
            }
        }
        (ib, bb)
    }

    /// Emits the barriers for one set of accesses as a single call.
    pub fn transition(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        images: &[(ImageId, AccessKind)],
        buffers: &[(BufferId, AccessKind)],
    ) {
        let (ib, bb) = self.plan(images, buffers);
        if ib.is_empty() && bb.is_empty() {
            return;
        }
        let dep = vk::DependencyInfo::default()
            .image_memory_barriers(&ib)
            .buffer_memory_barriers(&bb);
        unsafe { ctx.device.cmd_pipeline_barrier2(cmd, &dep) };
    }
}

/// Context handed to a pass's record closure.
pub struct PassContext<'a> {
    pub ctx: &'a Context,
    pub cmd: vk::CommandBuffer,
}

/// One pass: name, declared accesses, and the commands.
pub struct Pass<'a> {
    pub name: String,
    pub images: Vec<(ImageId, AccessKind)>,
    pub buffers: Vec<(BufferId, AccessKind)>,
    pub record: Box<dyn Fn(&PassContext) + 'a>,
}

impl<'a> Pass<'a> {
    pub fn new(name: impl Into<String>) -> Self {
        Pass {
            name: name.into(),
            images: Vec::new(),
            buffers: Vec::new(),
            record: Box::new(|_| {}),
        }
    }
    pub fn image(mut self, id: ImageId, access: AccessKind) -> Self {
        self.images.push((id, access));
        self
    }
    pub fn buffer(mut self, id: BufferId, access: AccessKind) -> Self {
        self.buffers.push((id, access));
        self
    }
    pub fn record(mut self, f: impl Fn(&PassContext) + 'a) -> Self {
        self.record = Box::new(f);
        self
    }
}

/// Records `passes` into `cmd` in order. With a profiler, pass `i` uses query
/// slots `i`; the caller reads them after the fence with the pass names.
pub fn record_passes(
    ctx: &Context,
    cmd: vk::CommandBuffer,
    resources: &mut Resources,
    passes: &[Pass],
    profiler: Option<&Profiler>,
) {
    if let Some(p) = profiler {
        assert!(
            passes.len() as u32 <= p.max_passes,
            "{} passes but the profiler holds {}",
            passes.len(),
            p.max_passes
        );
        p.reset(ctx, cmd);
    }
    for (i, pass) in passes.iter().enumerate() {
        let i = i as u32;
        ctx.begin_label(cmd, &pass.name);
        if let Some(p) = profiler {
            p.stamp(ctx, cmd, i, 0);
        }
        resources.transition(ctx, cmd, &pass.images, &pass.buffers);
        if let Some(p) = profiler {
            p.stamp(ctx, cmd, i, 1);
            p.begin_stats(ctx, cmd, i);
        }
        (pass.record)(&PassContext { ctx, cmd });
        if let Some(p) = profiler {
            p.end_stats(ctx, cmd, i);
            p.stamp(ctx, cmd, i, 2);
        }
        ctx.end_label(cmd);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ash::vk::Handle;

    fn range() -> vk::ImageSubresourceRange {
        vk::ImageSubresourceRange::default()
            .aspect_mask(vk::ImageAspectFlags::COLOR)
            .level_count(1)
            .layer_count(1)
    }

    // The SSS chain as the frame declares it: every barrier follows from the
    // previous access, and the second frame starts from the first one's end state.
    #[test]
    fn plans_the_sss_chain_and_carries_state_across_frames() {
        let mut r = Resources::default();
        let diffuse = r.add_image("diffuse", vk::Image::from_raw(1), range());
        let tmp = r.add_image("sss tmp", vk::Image::from_raw(2), range());
        for frame in 0..2 {
            // geometry writes diffuse
            let (ib, _) = r.plan(&[(diffuse, AccessKind::ColorAttachmentWrite)], &[]);
            assert_eq!(ib.len(), 1);
            assert_eq!(ib[0].old_layout, vk::ImageLayout::UNDEFINED);
            if frame == 1 {
                // WAR against last frame's composite read: execution dependency only.
                assert_eq!(
                    ib[0].src_stage_mask,
                    vk::PipelineStageFlags2::FRAGMENT_SHADER
                );
                assert_eq!(ib[0].src_access_mask, vk::AccessFlags2::NONE);
            }
            // seed: copy diffuse -> tmp
            let (ib, _) = r.plan(
                &[
                    (diffuse, AccessKind::TransferRead),
                    (tmp, AccessKind::TransferWrite),
                ],
                &[],
            );
            assert_eq!(ib.len(), 2);
            // sss_h: sample diffuse, write tmp (keeping the seeded texels)
            let (ib, _) = r.plan(
                &[
                    (diffuse, AccessKind::FragmentSampledRead),
                    (tmp, AccessKind::ColorAttachmentLoadWrite),
                ],
                &[],
            );
            assert_eq!(ib.len(), 2);
            assert_eq!(ib[1].old_layout, vk::ImageLayout::TRANSFER_DST_OPTIMAL);
            assert_eq!(ib[1].src_access_mask, vk::AccessFlags2::TRANSFER_WRITE);
            // sss_v: sample tmp, write back into diffuse
            let (ib, _) = r.plan(
                &[
                    (tmp, AccessKind::FragmentSampledRead),
                    (diffuse, AccessKind::ColorAttachmentLoadWrite),
                ],
                &[],
            );
            assert_eq!(ib.len(), 2);
            assert_eq!(ib[1].old_layout, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL);
            assert_eq!(ib[1].src_access_mask, vk::AccessFlags2::NONE);
            // composite samples diffuse
            let (ib, _) = r.plan(&[(diffuse, AccessKind::FragmentSampledRead)], &[]);
            assert_eq!(ib.len(), 1);
            // a second read in the same layout needs nothing
            let (ib, _) = r.plan(&[(diffuse, AccessKind::FragmentSampledRead)], &[]);
            assert!(ib.is_empty());
        }
    }

    #[test]
    fn buffers_get_barriers_only_after_writes() {
        let mut r = Resources::default();
        let b = r.add_buffer("readback", vk::Buffer::from_raw(7));
        let (_, bb) = r.plan(&[], &[(b, AccessKind::TransferWrite)]);
        assert!(bb.is_empty());
        let (_, bb) = r.plan(&[], &[(b, AccessKind::HostRead)]);
        assert_eq!(bb.len(), 1);
        assert_eq!(bb[0].src_access_mask, vk::AccessFlags2::TRANSFER_WRITE);
    }
}
