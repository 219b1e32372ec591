//! The submission objects of a renderer: its profiler, its one command
//! buffer and its fence, made (each guarded until all exist) and freed
//! together.

use anyhow::Result;
use ash::vk;

use crate::vk::context::Context;
use crate::vk::guard::{Destroy, Guard};
use crate::vk::profiler::Profiler;

/// The submission objects of a renderer.
pub(super) struct Submit {
    pub(super) profiler: Profiler,
    pub(super) cmd: vk::CommandBuffer,
    pub(super) fence: vk::Fence,
    /// CPU milliseconds the last submission spent recording its command buffer.
    pub(super) record_ms: std::cell::Cell<f64>,
}

impl Submit {
    pub(super) fn new(ctx: &Context, slots: u32) -> Result<Self> {
        // Each is guarded until the submit holds them all.
        let profiler = Guard::new(ctx, Profiler::new(ctx, slots)?);
        let cmd = ctx.create("frame commands", |d| unsafe {
            d.allocate_command_buffers(
                &vk::CommandBufferAllocateInfo::default()
                    .command_pool(ctx.command_pool)
                    .command_buffer_count(1),
            )
        })?[0];
        let cmd = Guard::new(ctx, cmd);
        ctx.name(*cmd, "frame commands");
        let fence = ctx.create("frame fence", |d| unsafe {
            d.create_fence(&vk::FenceCreateInfo::default(), None)
        })?;
        ctx.name(fence, "frame fence");
        Ok(Submit {
            profiler: profiler.keep(),
            cmd: cmd.keep(),
            fence,
            record_ms: std::cell::Cell::new(0.0),
        })
    }
}

impl Destroy for Submit {
    fn destroy(&mut self, ctx: &Context) {
        self.fence.destroy(ctx);
        self.cmd.destroy(ctx);
        Destroy::destroy(&mut self.profiler, ctx);
    }
}
