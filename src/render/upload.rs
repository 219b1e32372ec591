//! Uploads of textures and buffers at set-up (one-shot command buffers). The
//! barriers come from the same access table as the frame's.

use anyhow::{Context as _, Result};
use ash::vk;
use gpu_allocator::MemoryLocation;

use crate::graph::Resources;
use crate::vk::barrier::AccessKind;
use crate::vk::context::Context;
use crate::vk::memory::{Buffer, Image};

/// Creates a sampled image and fills it with `bytes` (tightly packed texels).
pub fn texture(
    ctx: &Context,
    name: &str,
    extent: vk::Extent2D,
    format: vk::Format,
    bytes: &[u8],
) -> Result<Image> {
    let image = Image::new(
        ctx,
        name,
        extent,
        format,
        vk::ImageUsageFlags::SAMPLED | vk::ImageUsageFlags::TRANSFER_DST,
    )?;
    fill_image(
        ctx,
        &image,
        vk::ImageAspectFlags::COLOR,
        bytes,
        AccessKind::AnyShaderSampledRead,
    )
    .with_context(|| format!("uploading texture '{name}'"))?;
    Ok(image)
}

/// Copies `bytes` into one aspect of `image` and leaves it in `final_access`.
pub fn fill_image(
    ctx: &Context,
    image: &Image,
    aspect: vk::ImageAspectFlags,
    bytes: &[u8],
    final_access: AccessKind,
) -> Result<()> {
    let mut staging = Buffer::with_data(
        ctx,
        &format!("{} staging", image.name),
        bytes,
        vk::BufferUsageFlags::TRANSFER_SRC,
    )?;
    let mut res = Resources::default();
    let id = res.add_image(&image.name, image.raw, image.subresource_range());
    let result = ctx.one_shot(&format!("upload {}", image.name), |cmd| {
        res.transition(ctx, cmd, &[(id, AccessKind::TransferWrite)], &[]);
        let region = vk::BufferImageCopy::default()
            .image_subresource(
                vk::ImageSubresourceLayers::default()
                    .aspect_mask(aspect)
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
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &[region],
            )
        };
        res.transition(ctx, cmd, &[(id, final_access)], &[]);
    });
    staging.destroy(ctx);
    result
}

/// Fills both aspects of a D32S8 depth/stencil image in one submission (two
/// separate uploads would each discard the other's contents).
pub fn fill_depth_stencil(
    ctx: &Context,
    image: &Image,
    depth: &[f32],
    stencil: &[u8],
    final_access: AccessKind,
) -> Result<()> {
    if image.format != vk::Format::D32_SFLOAT_S8_UINT {
        anyhow::bail!(
            "depth/stencil uploads need D32_SFLOAT_S8_UINT, the image is {:?}",
            image.format
        );
    }
    let mut bytes: Vec<u8> = bytemuck::cast_slice(depth).to_vec();
    let stencil_offset = bytes.len() as u64;
    bytes.extend_from_slice(stencil);
    let mut staging = Buffer::with_data(
        ctx,
        &format!("{} staging", image.name),
        &bytes,
        vk::BufferUsageFlags::TRANSFER_SRC,
    )?;
    let mut res = Resources::default();
    let id = res.add_image(&image.name, image.raw, image.subresource_range());
    let extent = vk::Extent3D {
        width: image.extent.width,
        height: image.extent.height,
        depth: 1,
    };
    let result = ctx.one_shot(&format!("upload {}", image.name), |cmd| {
        res.transition(ctx, cmd, &[(id, AccessKind::TransferWrite)], &[]);
        let region = |aspect, offset| {
            vk::BufferImageCopy::default()
                .buffer_offset(offset)
                .image_subresource(
                    vk::ImageSubresourceLayers::default()
                        .aspect_mask(aspect)
                        .layer_count(1),
                )
                .image_extent(extent)
        };
        unsafe {
            ctx.device.cmd_copy_buffer_to_image(
                cmd,
                staging.raw,
                image.raw,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &[
                    region(vk::ImageAspectFlags::DEPTH, 0),
                    region(vk::ImageAspectFlags::STENCIL, stencil_offset),
                ],
            )
        };
        res.transition(ctx, cmd, &[(id, final_access)], &[]);
    });
    staging.destroy(ctx);
    result
}

/// A device-local vertex or index buffer with `bytes` in it. (Uniform buffers
/// are host-visible instead: host writes before a submit need no barrier.)
pub fn device_buffer(
    ctx: &Context,
    name: &str,
    bytes: &[u8],
    usage: vk::BufferUsageFlags,
    first_use: AccessKind,
) -> Result<Buffer> {
    let mut staging = Buffer::with_data(
        ctx,
        &format!("{name} staging"),
        bytes,
        vk::BufferUsageFlags::TRANSFER_SRC,
    )?;
    let buffer = Buffer::new(
        ctx,
        name,
        bytes.len() as u64,
        usage | vk::BufferUsageFlags::TRANSFER_DST,
        MemoryLocation::GpuOnly,
    )?;
    let mut res = Resources::default();
    let id = res.add_buffer(name, buffer.raw);
    let result = ctx.one_shot(&format!("upload {name}"), |cmd| {
        res.transition(ctx, cmd, &[], &[(id, AccessKind::TransferWrite)]);
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
        res.transition(ctx, cmd, &[], &[(id, first_use)]);
    });
    staging.destroy(ctx);
    result?;
    Ok(buffer)
}
