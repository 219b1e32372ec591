//! Uploads of textures and buffers at set-up (one-shot command buffers). The
//! barriers come from the same planner and access table as the frame's.

use anyhow::{Context as _, Result};
use ash::vk;
use gpu_allocator::MemoryLocation;

use super::barrier::{image_barrier, AccessKind, ResourceState};
use super::context::Context;
use super::guard::Guard;
use super::memory::{Buffer, Image};

/// Creates a sampled image and fills it with `bytes` (tightly packed texels),
/// leaving it readable by fragment and compute shaders.
pub fn texture(
    ctx: &Context,
    name: &str,
    extent: vk::Extent2D,
    format: vk::Format,
    bytes: &[u8],
) -> Result<Image> {
    let first_use = AccessKind::AnyShaderSampledRead;
    let image = Guard::new(
        ctx,
        Image::new(
            ctx,
            name,
            extent,
            format,
            first_use.image_usage() | AccessKind::TransferWrite.image_usage(),
        )?,
    );
    fill(ctx, &image, bytes, first_use).with_context(|| format!("uploading texture '{name}'"))?;
    Ok(image.keep())
}

/// Copies `bytes` into the colour aspect of a fresh `image` and leaves it in
/// `final_access`.
fn fill(ctx: &Context, image: &Image, bytes: &[u8], final_access: AccessKind) -> Result<()> {
    // Freed when this returns: after the upload's fence, or at once on an error.
    let staging = Guard::new(
        ctx,
        Buffer::with_data(
            ctx,
            &format!("{} staging", image.name),
            bytes,
            vk::BufferUsageFlags::TRANSFER_SRC,
        )?,
    );
    let mut state = ResourceState::default();
    let range = image.subresource_range();
    let mut barrier = |cmd, next| {
        if let Some(p) = state.plan(next, true) {
            let b = [image_barrier(&p, image.raw, range)];
            let dep = vk::DependencyInfo::default().image_memory_barriers(&b);
            unsafe { ctx.device.cmd_pipeline_barrier2(cmd, &dep) };
        }
    };
    ctx.one_shot(&format!("upload {}", image.name), |cmd| {
        barrier(cmd, AccessKind::TransferWrite);
        let region = vk::BufferImageCopy::default()
            .image_subresource(
                vk::ImageSubresourceLayers::default()
                    .aspect_mask(vk::ImageAspectFlags::COLOR)
                    .layer_count(1),
            )
            .image_extent(vk::Extent3D {
                width: image.extent.width,
                height: image.extent.height,
                depth: 1,
            });
        unsafe {
            ctx.device.cmd_copy_buffer_to_image(
                cmd,
                staging.raw,
                image.raw,
                AccessKind::TransferWrite.info().layout,
                &[region],
            )
        };
        barrier(cmd, final_access);
    })
}

/// A device-local buffer with `bytes` in it, ready for `first_use`. (Uniform
/// buffers are host-visible instead: host writes before a submit need no barrier.)
pub fn device_buffer(
    ctx: &Context,
    name: &str,
    bytes: &[u8],
    usage: vk::BufferUsageFlags,
    first_use: AccessKind,
) -> Result<Buffer> {
    // Freed when this returns: after the upload's fence, or at once on an error.
    let staging = Guard::new(
        ctx,
        Buffer::with_data(
            ctx,
            &format!("{name} staging"),
            bytes,
            vk::BufferUsageFlags::TRANSFER_SRC,
        )?,
    );
    let buffer = Guard::new(
        ctx,
        Buffer::new(
            ctx,
            name,
            bytes.len() as u64,
            usage | vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuOnly,
        )?,
    );
    let mut state = ResourceState::default();
    let mut barrier = |cmd, next| {
        if let Some(p) = state.plan(next, false) {
            let b = [vk::BufferMemoryBarrier2::default()
                .src_stage_mask(p.src_stage)
                .src_access_mask(p.src_access)
                .dst_stage_mask(p.dst_stage)
                .dst_access_mask(p.dst_access)
                .buffer(buffer.raw)
                .offset(0)
                .size(vk::WHOLE_SIZE)];
            let dep = vk::DependencyInfo::default().buffer_memory_barriers(&b);
            unsafe { ctx.device.cmd_pipeline_barrier2(cmd, &dep) };
        }
    };
    ctx.one_shot(&format!("upload {name}"), |cmd| {
        barrier(cmd, AccessKind::TransferWrite);
        unsafe {
            ctx.device.cmd_copy_buffer(
                cmd,
                staging.raw,
                buffer.raw,
                &[vk::BufferCopy {
                    src_offset: 0,
                    dst_offset: 0,
                    size: bytes.len() as u64,
                }],
            )
        };
        barrier(cmd, first_use);
    })?;
    Ok(buffer.keep())
}
