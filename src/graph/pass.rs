//! A pass: a name (a label, nothing else keys on it), its role, its declared
//! work, its declared accesses, and a record closure; and the executor that
//! records a list of them.

use ash::vk;

use super::resources::{BufferId, ImageId, Resources};
use super::work::{PassRole, Work};
use crate::vk::barrier::AccessKind;
use crate::vk::context::Context;
use crate::vk::memory::Image;
use crate::vk::profiler::{PassTiming, Profiler};

/// What a pass's record closure gets: the device, the command buffer, and the
/// graph's images as this pass declared them.
pub struct PassContext<'a> {
    pub ctx: &'a Context,
    pub cmd: vk::CommandBuffer,
    pub res: &'a Resources,
    pass: &'a str,
    images: &'a [(ImageId, AccessKind)],
}

impl PassContext<'_> {
    fn access(&self, id: ImageId) -> AccessKind {
        self.images
            .iter()
            .find(|(i, _)| *i == id)
            .map(|(_, a)| *a)
            .unwrap_or_else(|| {
                panic!(
                    "pass '{}' records with image '{}' it did not declare",
                    self.pass,
                    self.res.name(id)
                )
            })
    }

    /// The layout `id` is in during this pass: the one of the access the pass
    /// declared for it (never typed at the call site).
    pub fn layout(&self, id: ImageId) -> vk::ImageLayout {
        self.access(id).info().layout
    }

    /// The view of the level `id` names (declared by this pass).
    pub fn view(&self, id: ImageId) -> vk::ImageView {
        self.access(id);
        self.res.view(id)
    }

    /// The image behind `id` (declared by this pass).
    pub fn image(&self, id: ImageId) -> &Image {
        self.access(id);
        self.res.image(id)
    }
}

type Record<'a> = Box<dyn Fn(&PassContext) + 'a>;

/// One pass: name, role, work, declared accesses, and the commands.
pub struct Pass<'a> {
    pub name: String,
    pub role: PassRole,
    /// What the pass costs per unit of work; `None` only for passes that record
    /// nothing (e.g. the host-visibility step of a readback).
    pub work: Option<Work>,
    pub images: Vec<(ImageId, AccessKind)>,
    pub buffers: Vec<(BufferId, AccessKind)>,
    pub record: Record<'a>,
}

impl<'a> Pass<'a> {
    pub fn new(name: impl Into<String>, role: PassRole) -> Self {
        Pass {
            name: name.into(),
            role,
            work: None,
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
    pub fn work(mut self, work: Work) -> Self {
        self.work = Some(work);
        self
    }
    pub fn record(mut self, f: impl Fn(&PassContext) + 'a) -> Self {
        self.record = Box::new(f);
        self
    }
}

/// What the GPU measured for one pass in one frame.
#[derive(Clone, Debug, PartialEq)]
pub struct PassSample {
    pub name: String,
    pub role: PassRole,
    pub barrier_ms: f64,
    pub gpu_ms: f64,
    pub fragment_invocations: Option<u64>,
    pub samples_passed: u64,
}

impl PassSample {
    pub fn new(pass: &Pass, t: PassTiming) -> Self {
        PassSample {
            name: pass.name.clone(),
            role: pass.role,
            barrier_ms: t.barrier_ms,
            gpu_ms: t.gpu_ms,
            fragment_invocations: t.fragment_invocations,
            samples_passed: t.samples_passed,
        }
    }
}

/// Records `passes` into `cmd` in order. With a profiler, pass `i` uses query
/// slots `i`; the caller reads them after the fence.
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
        (pass.record)(&PassContext {
            ctx,
            cmd,
            res: resources,
            pass: &pass.name,
            images: &pass.images,
        });
        if let Some(p) = profiler {
            p.end_stats(ctx, cmd, i);
            p.stamp(ctx, cmd, i, 2);
        }
        ctx.end_label(cmd);
    }
}
