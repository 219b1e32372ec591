//! One-shot submissions: record a command buffer, submit it and wait. Apart
//! from `context.rs` because the command buffer and the fence are guarded
//! (`guard.rs`), and the guard itself names the context.

use anyhow::{Context as _, Result};
use ash::vk;

use super::context::Context;
use super::error::Error;
use super::guard::Guard;

impl Context {
    /// Records and submits one command buffer and waits for it.
    pub fn one_shot(&self, label: &str, record: impl FnOnce(vk::CommandBuffer)) -> Result<()> {
        let cmd = self.create(label, |d| unsafe {
            d.allocate_command_buffers(
                &vk::CommandBufferAllocateInfo::default()
                    .command_pool(self.command_pool)
                    .command_buffer_count(1),
            )
        })?[0];
        // Freed when this returns: after the wait, or at once on an error.
        let cmd = Guard::new(self, cmd);
        self.name(*cmd, label);
        unsafe {
            self.device.begin_command_buffer(
                *cmd,
                &vk::CommandBufferBeginInfo::default()
                    .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT),
            )
        }
        .map_err(Error::from)
        .with_context(|| format!("beginning '{label}'"))?;
        record(*cmd);
        self.submit_and_wait(*cmd)
            .with_context(|| format!("submitting '{label}'"))
    }

    /// Ends, submits and waits for a recorded command buffer.
    pub fn submit_and_wait(&self, cmd: vk::CommandBuffer) -> Result<()> {
        unsafe { self.device.end_command_buffer(cmd) }.map_err(Error::from)?;
        let fence = unsafe {
            self.device
                .create_fence(&vk::FenceCreateInfo::default(), None)
        }
        .map_err(Error::from)?;
        // Destroyed when this returns, after the wait (or its failure).
        let fence = Guard::new(self, fence);
        let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(cmd)];
        let submit = [vk::SubmitInfo2::default().command_buffer_infos(&cmds)];
        unsafe {
            self.device
                .queue_submit2(self.queue, &submit, *fence)
                .and_then(|_| self.device.wait_for_fences(&[*fence], true, u64::MAX))
        }
        .map_err(Error::from)
        .context("queue submit / wait (device lost?)")
    }
}
